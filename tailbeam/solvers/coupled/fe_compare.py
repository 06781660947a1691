"""The modal solver against the full-FE reference (``fe_reference``): one impact, its contact
quantities and the in-band acceleration at a sensor. Used by the tests and by
benchmarks/study_coupled_fe.py (the convergence study against the band).
"""

from dataclasses import dataclass

import numpy as np

from tailbeam.physics.contact_patch import load_radius
from tailbeam.solvers.coupled.fe_reference import (
    QUANTITIES,
    fe_reference,
    impact_quantities,
    in_band,
    relative_l2,
)
from tailbeam.solvers.coupled.solver import simulate_coupled

SENSOR_BAND_HZ = 10_000.0  # the compared sensor band, 0-10 kHz
SENSOR_WINDOW_S = 3e-3  # compared over the first 3 ms
RECORD_S = 3.5e-3  # simulated: the window plus room for the zero-phase filter's end transient


@dataclass
class Case:
    """One impact on one FE plate: the assembled model, the ball, its law and a sensor."""

    model: object
    ball: object
    law: object
    sensor: tuple
    gravity: float = 9.80665
    rayleigh: tuple = (0.0, 0.0)
    sensor_band_hz: float = SENSOR_BAND_HZ
    sensor_window_s: float = SENSOR_WINDOW_S

    @property
    def load_radius(self) -> float:
        return load_radius(self.model.theory, self.ball, self.law, self.gravity)

    def reference(self, dt: float, duration: float = RECORD_S, **options):
        """The FE reference of this case (``fe_reference``) with the case's load model."""
        return fe_reference(self.model, self.ball, self.law, duration, dt=dt,
                            load_radius=self.load_radius, sensors=[self.sensor],
                            rayleigh=self.rayleigh, gravity=self.gravity, **options)  # fmt: skip

    def read(self, res, t, quasi_static: bool) -> np.ndarray:
        """The sensor's acceleration (m/s^2) in the coupled result ``res`` at times t (s)."""
        return res.plate.sample(t, [self.sensor], quasi_static=quasi_static)["a"][0]


def modal_errors(case: Case, basis, ref, **options) -> dict:
    """Relative errors of ``simulate_coupled`` on ``basis`` against the reference ``ref``:
    each contact quantity of the first impact, their maximum ("contact"), and the in-band
    sensor acceleration with ("sensor") and without ("sensor_no_qs") the truncated modes'
    quasi-static part. ``options`` go to simulate_coupled (damping 0 unless given)."""
    options.setdefault("damping_ratio", 0.0)
    if case.rayleigh != (0.0, 0.0):
        options["rayleigh"] = case.rayleigh
    duration = float(ref.t[-1])
    res = simulate_coupled([case.ball], basis, [case.law], duration, gravity=case.gravity,
                           **options)  # fmt: skip
    return dict(result_errors(case, res, ref), n_modes=basis.n_modes)


def result_errors(case: Case, res, ref) -> dict:
    """Relative errors of a coupled result ``res`` of ``case`` (however it was run, e.g. a
    scene through simulate_scene_modal) against the reference ``ref``: as modal_errors."""
    q, q_ref = impact_quantities(res.impacts[0]), impact_quantities(ref.impacts[0])
    out = {name: abs(q[name] / q_ref[name] - 1.0) for name in QUANTITIES}
    out["contact"] = max(out[name] for name in QUANTITIES)
    # filtered at the reference's own step: decimating first would alias the FE model's
    # high modes (up to MHz) into the band
    t = ref.t
    a_ref = in_band(t, ref.sensor_a[0], case.sensor_band_hz)
    win = t <= case.sensor_window_s
    for key, qs in (("sensor", True), ("sensor_no_qs", False)):
        a = case.read(res, t, qs)
        out[key] = relative_l2(in_band(t, a, case.sensor_band_hz)[win], a_ref[win])
    return out


def observed_order(bands, errors) -> float:
    """Least-squares slope of -log(error) against log(band): error ~ band^-order."""
    x, y = np.log(np.asarray(bands, float)), np.log(np.asarray(errors, float))
    return float(-np.polyfit(x, y, 1)[0])
