"""The full finite-element reference of one impact on a structure from a volume mesh.

The plate's reference (``tailbeam.solvers.coupled.fe_reference``: Newmark average
acceleration on every DOF, the IMPACT law solved implicitly each step, contact start and end
located inside their step) run on a ``tailbeam.plate.solid.StructureModel``: its stiffness
(the supports' springs included) and mass on the held DOFs, the contact's 1 N spread over the
same disc of the impact face as the modal path spreads it (``StructureModel.load_vector``,
the disc of ``load_radius`` for the theory "solid"), and sensors anywhere on the surface read
from the full displacement along their direction (``StructureModel.surface_operator``). The
effective stiffness is factorised as the structure's own matrices are (METIS nested
dissection, ``tailbeam.plate.solid.factor``). ``StructureCase`` is the plate's comparison
``Case`` on a structure (``fe_compare.modal_errors`` runs on it unchanged).
"""

from dataclasses import dataclass

import numpy as np

from tailbeam.errors import InputError
from tailbeam.physics.bodies import STANDARD_GRAVITY
from tailbeam.physics.contact_patch import load_radius
from tailbeam.plate.solid.factor import factorize
from tailbeam.plate.solid.modes import THEORY
from tailbeam.signals.sensor import SensorSpec
from tailbeam.solvers.coupled.fe_compare import RECORD_S, Case
from tailbeam.solvers.coupled.fe_reference import (
    DEFAULT_MAX_WORK,
    FEReferenceResult,
    check_inputs,
    integrate,
)


def sensor_operator(model, sensors):
    """(p, n) sparse: the displacement (m) along each channel of ``sensors`` (SensorSpecs;
    three-axis ones give one row per axis) from the structure's reduced DOFs, or None."""
    channels = [c for spec in sensors for c in spec.channels()]
    if not channels:
        return None
    pts = [tuple(c.position) + (0.0,) * (3 - len(c.position)) for c in channels]
    dirs = [c.direction if c.direction is not None else (0.0, 0.0, 1.0) for c in channels]
    names = ", ".join(f"sensors[{c.name}].position" for c in channels)
    return model.surface_operator(np.array(pts, float), np.array(dirs, float), names)


def structure_fe_reference(
    model,
    ball,
    law,
    duration: float,
    *,
    dt: float,
    load_radius: float = 0.0,
    sensors=(),
    rayleigh=(0.0, 0.0),
    gravity: float = STANDARD_GRAVITY,
    max_work: float = DEFAULT_MAX_WORK,
) -> FEReferenceResult:
    """One ball on the structure ``model`` over [0, duration] s (see the module docstring).

    dt: Newmark step (s); load_radius: radius (m) of the disc of the impact face the contact
    force is spread over; sensors: SensorSpecs on the surface (``sensor_a`` holds one row per
    channel, m/s^2 along its direction; ``sensor_w`` the displacement, m); rayleigh: (alpha
    1/s, beta s). WorkLimitError before any work if steps x 10 x matrix nonzeros exceeds
    ``max_work``.
    """
    check_inputs(ball, law, model, duration, dt, load_radius)
    if any(not isinstance(s, SensorSpec) for s in sensors):
        raise InputError("sensors", "must be SensorSpec objects")
    load = model.load_vector(ball.position[:2], load_radius)
    return integrate(model, ball, law, duration, dt=dt, load=load,
                     probe=sensor_operator(model, sensors), rayleigh=rayleigh, gravity=gravity,
                     max_work=max_work, info={"load_radius": load_radius},
                     factorize=factorize)  # fmt: skip


@dataclass
class StructureCase(Case):
    """One impact on a structure: ``model`` a StructureModel, ``sensor`` a single-direction
    SensorSpec anywhere on its surface; otherwise the plate's ``Case``."""

    @property
    def load_radius(self) -> float:
        return load_radius(THEORY, self.ball, self.law, self.gravity)

    def reference(self, dt: float, duration: float = RECORD_S, **options):
        """The full FE reference of this case (``structure_fe_reference``)."""
        return structure_fe_reference(self.model, self.ball, self.law, duration, dt=dt,
                                      load_radius=self.load_radius, sensors=[self.sensor],
                                      rayleigh=self.rayleigh, gravity=self.gravity,
                                      **options)  # fmt: skip

    def read(self, res, t, quasi_static: bool) -> np.ndarray:
        """The sensor channel's acceleration (m/s^2) in the coupled result ``res``."""
        return res.plate.channel_sample(t, [self.sensor], quasi_static=quasi_static)["a"][0]
