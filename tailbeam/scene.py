"""A scene in memory: what to simulate (balls, plate, contact settings, sensors).

Reading scene files lives in ``tailbeam.io.scene_file``; this module holds no I/O.
"""

import functools
import math
from dataclasses import dataclass, field, replace

from tailbeam.errors import (
    InputError,
    require_nonnegative,
    require_positive,
    require_vector,
)
from tailbeam.physics.bodies import STANDARD_GRAVITY, Ball, Plate
from tailbeam.physics.contact_law import HERTZ_EXPONENT, ImpactLaw, ball_plate_law
from tailbeam.physics.contacts import PLATE, ContactTable
from tailbeam.physics.friction import FrictionModel
from tailbeam.physics.incline import InclinedPlate
from tailbeam.physics.materials import Material
from tailbeam.signals.sensor import SensorSpec
from tailbeam.streams.generator import Particle, default_label, particles_from_settings

# Defaults where the paper is silent (docs/reproduction.md, "Defaults"). d = 0.1 mm is Adams'
# default penetration depth. c = 300 N s/m was chosen by running the paper's three scenarios over a
# grid of (c, d, drop gap) and keeping every qualitative claim of sections 4.1-4.3 and conclusions
# 1-3 true (tailbeam.paper.claims, benchmarks/claim_map.py): with d = 0.1 mm all claims hold on the
# grid for c = 300-350 N s/m at every drop gap 0-10 mm, and c = 300 is the one grid value that also
# holds at 20 mm. The binding claim is 4.3 (coal rebounds above sandstone after collisions 1-2 and
# below from the 3rd), which needs e_sand / e_coal of about 1.1. At ~1 m/s c = 300 gives
# restitution 0.84 (coal) and 0.92 (sandstone) on steel; Adams' own default, c = 10 N s/mm, makes
# coal nearly plastic (e ~ 0.1) and breaks 4.3 and 4.1.
DEFAULT_DAMPING = 300.0  # c, N s/m
DEFAULT_PENETRATION = 1e-4  # d, m (Adams' default 0.1 mm)

PLATE_MODELS = ("rigid", "modal")
LABELS = ("coal", "gangue")
THEORIES = ("auto", "kirchhoff", "mindlin")
COUPLINGS = ("two-way", "one-way")
TAILS = ("auto", "quasi-static", "ritz")
DEFAULT_TAIL_MODES = 32  # Ritz pseudo-modes per contact point (docs/fe-convergence.md)
DEFAULT_IMPACT_FACE = "top"  # plate.impact_face of a structure from plate.mesh
STREAM_TAIL_MODES = 4  # a stream contact's tail oscillators (tailbeam.plate.contact_tail)


@dataclass(frozen=True)
class ContactSettings:
    """The IMPACT parameters shared by every ball-plate pair of a scene.

    exponent e, damping c in N s/m, penetration d in m, clamp = Adams' max(0, .).
    """

    exponent: float = HERTZ_EXPONENT
    damping: float = DEFAULT_DAMPING
    penetration: float = DEFAULT_PENETRATION
    clamp: bool = True

    def __post_init__(self):
        # ImpactLaw validates the same fields; build one to fail early with field names.
        ImpactLaw(1.0, self.exponent, self.damping, self.penetration, self.clamp)

    def law_for(self, ball: Ball, plate_material: Material) -> ImpactLaw:
        """The ball-plate law: Hertz stiffness of the ball on the flat plate (eqs. 4-6)."""
        return ball_plate_law(
            ball.material,
            ball.radius,
            plate_material,
            exponent=self.exponent,
            damping=self.damping,
            penetration=self.penetration,
            clamp=self.clamp,
        )


@dataclass(frozen=True)
class ModalPlateSettings:
    """How to model a flexible plate.

    boundary: four letters C/S/F for the edges left (x=-a/2), bottom (y=-b/2), right (x=+a/2),
    top (y=+b/2). theory: "auto" | "kirchhoff" | "mindlin". damping_ratio: modal damping ratio
    of every mode, unless rayleigh = (alpha in 1/s, beta in s) is given. fmax_hz: highest mode
    frequency kept (None: chosen from the scene). mesh_divisions: elements per side (None: auto).
    residual_flexibility: add the static compliance of the truncated modes at contacts.
    coupling: "two-way" or "one-way" (rigid-plate forces applied to the plate).
    tail: how the truncated modes act at a contact: "quasi-static" (their static compliance),
    "ritz" (on the single-ball solver load-dependent Ritz pseudo-modes at the balls' first
    contact points, tailbeam.solvers.modal_setup.ritz_prepass; on the stream solver a few
    oscillators at every plate contact, tailbeam.plate.contact_tail; needs
    residual_flexibility and two-way coupling) or "auto" (the default: "ritz" where it
    applies and its cost is bounded, "quasi-static" elsewhere, saying why).
    tail_modes: Ritz pseudo-modes per contact point, a whole number >= 1, "auto" (chosen per
    point, a posteriori, 0.9-2.5 s per point; the coupled solver only) or None: the solver's
    default, 32 on the coupled solver (within 2e-5 of the full FE at 20 kHz on the default
    and the test meshes), 4 per contact on the stream solver (``tail_modes_for``).
    mesh: a volume mesh file (absolute path) of the structure (None: the flat rectangular
    plate); impact_face: its named face where particles land (default "top");
    supports: tailbeam.plate.solid.Support of each ``[[plate.supports]]``
    (docs/structures.md).
    """

    boundary: str = "SSSS"
    theory: str = "auto"
    damping_ratio: float = 0.01
    rayleigh: tuple[float, float] | None = None
    fmax_hz: float | None = None
    mesh_divisions: int | None = None
    residual_flexibility: bool = True
    coupling: str = "two-way"
    tail: str = "auto"
    tail_modes: int | str | None = None
    mesh: str | None = None
    impact_face: str | None = None
    supports: tuple = ()

    def __post_init__(self):
        self._check_structure()
        code = self.boundary
        if not (isinstance(code, str) and len(code) == 4 and set(code.upper()) <= set("CSF")):
            raise InputError(
                "plate.boundary",
                f"must be four letters from C, S, F (edges left, bottom, right, top), got {code!r}",
            )
        object.__setattr__(self, "boundary", code.upper())
        if self.theory not in THEORIES:
            raise InputError("plate.theory", f"must be one of {THEORIES}, got {self.theory!r}")
        if self.coupling not in COUPLINGS:
            raise InputError("plate.coupling", f"must be one of {COUPLINGS}, got {self.coupling!r}")
        require_nonnegative("plate.damping_ratio", self.damping_ratio)
        if self.damping_ratio >= 1.0:
            raise InputError(
                "plate.damping_ratio",
                f"must be < 1 (an underdamped plate; welded steel is ~0.001-0.05), "
                f"got {self.damping_ratio!r}",
            )
        if self.rayleigh is not None:
            alpha, beta = require_vector("plate.rayleigh", self.rayleigh, 2)
            require_nonnegative("plate.rayleigh[0]", alpha)
            require_nonnegative("plate.rayleigh[1]", beta)
            object.__setattr__(self, "rayleigh", (alpha, beta))
        if self.fmax_hz is not None:
            object.__setattr__(self, "fmax_hz", require_positive("plate.fmax", self.fmax_hz))
        if self.mesh_divisions is not None:
            n = self.mesh_divisions
            if isinstance(n, bool) or not isinstance(n, int) or n < 1:
                raise InputError("plate.mesh_divisions", f"must be a whole number >= 1, got {n!r}")
        self._check_tail()

    def _check_structure(self):
        if self.mesh is None:
            for key, value in (("impact_face", self.impact_face), ("supports", self.supports)):
                if value:
                    raise InputError(f"plate.{key}", "needs plate.mesh (a structure's mesh file)")
            return
        if self.impact_face is None:
            object.__setattr__(self, "impact_face", DEFAULT_IMPACT_FACE)
        object.__setattr__(self, "supports", tuple(self.supports))

    def tail_modes_for(self, stream: bool) -> int | str:
        """plate.tail_modes as the solver uses it: the set value, else its default
        (STREAM_TAIL_MODES on the stream solver, DEFAULT_TAIL_MODES on the coupled one)."""
        if self.tail_modes is not None:
            return self.tail_modes
        return STREAM_TAIL_MODES if stream else DEFAULT_TAIL_MODES

    def _check_tail(self):
        if self.tail not in TAILS:
            raise InputError("plate.tail", f"must be one of {TAILS}, got {self.tail!r}")
        k = self.tail_modes
        whole = isinstance(k, int) and not isinstance(k, bool) and k >= 1
        if k is not None and k != "auto" and not whole:
            raise InputError(
                "plate.tail_modes", f"must be 'auto' or a whole number >= 1, got {k!r}"
            )
        if self.tail == "ritz" and not (self.residual_flexibility and self.coupling == "two-way"):
            raise InputError(
                "plate.tail",
                "'ritz' refines the residual flexibility of two-way coupling; it needs "
                "residual_flexibility = true and coupling = 'two-way'",
            )


@dataclass(frozen=True)
class Scene:
    """Everything that defines one simulation.

    duration in s, sample_rate (output) in Hz, gravity: its magnitude in m/s^2 (0 for none),
    along -z of the horizontal plate; inclination: the plate's tilt in degrees, [0, 90), about
    its y axis (x points downhill; positions and velocities are in the plate frame, gravity
    there is g (sin theta, 0, -cos theta), tailbeam.physics.incline). streams: validated
    stream settings (tailbeam.streams.generator.StreamSettings); their particles
    (``particles``) are generated deterministically from the seeds when first asked for.
    labels: ``coal`` or ``gangue`` per ball (default: ``default_label``). friction: the
    contacts' friction and rolling resistance (``tailbeam.physics.friction.FrictionModel``),
    None for frictionless contacts (the paper's setting).
    """

    balls: tuple[Ball, ...]
    plate: Plate = field(default_factory=Plate)
    contact: ContactSettings = field(default_factory=ContactSettings)
    duration: float = 1.0
    sample_rate: float = 10000.0
    plate_model: str = "rigid"
    modal: ModalPlateSettings | None = None
    sensors: tuple[SensorSpec, ...] = ()
    gravity: float = STANDARD_GRAVITY
    inclination: float = 0.0
    streams: tuple = ()
    labels: tuple[str, ...] = ()
    friction: FrictionModel | None = None

    def __post_init__(self):
        require_positive("duration", self.duration)
        require_positive("sample_rate", self.sample_rate)
        object.__setattr__(self, "gravity", require_nonnegative("gravity", self.gravity))
        object.__setattr__(self, "balls", tuple(self.balls))
        object.__setattr__(self, "streams", tuple(self.streams))
        object.__setattr__(self, "inclination", self.incline.inclination)  # validates it
        if self.plate_model not in PLATE_MODELS:
            raise InputError(
                "plate.model", f"must be one of {PLATE_MODELS}, got {self.plate_model!r}"
            )
        if not self.balls and not self.streams:
            raise InputError("balls", "a scene needs at least one ball or stream")
        names = [b.name for b in self.balls]
        dup = {n for n in names if names.count(n) > 1}
        if dup:
            raise InputError("balls", f"ball names must be unique; repeated: {sorted(dup)}")
        if PLATE in names:
            raise InputError(
                f"balls[{names.index(PLATE) + 1}].name",
                f"{PLATE!r} names the plate (the partner column of impacts.csv, the contact "
                "table); choose another name",
            )
        self._check_labels()
        self._check_streams()
        if self.friction is not None and not isinstance(self.friction, FrictionModel):
            raise InputError("contact.friction", "must be a FrictionModel (or None: frictionless)")
        sensor_names = [s.name for s in self.sensors]
        if len(set(sensor_names)) != len(sensor_names):
            raise InputError("sensors", "sensor names must be unique")
        if self.plate_model == "modal" and self.modal is None:
            object.__setattr__(self, "modal", ModalPlateSettings())
        if self.modal is not None and self.modal.tail_modes is None:  # the solver's default
            k = self.modal.tail_modes_for(self.needs_stream_solver)
            object.__setattr__(self, "modal", replace(self.modal, tail_modes=k))

    def _check_labels(self) -> None:
        labels = tuple(self.labels) or tuple(default_label(b) for b in self.balls)
        if len(labels) != len(self.balls):
            raise InputError("labels", f"must give one label per ball ({len(self.balls)})")
        for i, label in enumerate(labels, start=1):
            if label not in LABELS:
                raise InputError(f"balls[{i}].label", f"must be one of {LABELS}, got {label!r}")
        object.__setattr__(self, "labels", labels)

    def _check_streams(self) -> None:
        names = {b.name for b in self.balls}
        streams = [s.name for s in self.streams]
        for i, s in enumerate(self.streams, start=1):
            field_ = f"streams[{i}]"
            if s.name in streams[: i - 1]:
                raise InputError(f"{field_}.name", f"{s.name!r} is used by an earlier stream")
            if s.start >= self.duration:
                raise InputError(
                    f"{field_}.start",
                    f"must be < duration = {self.duration!r} s (nothing would be released), "
                    f"got {s.start!r}",
                )
            prefix = f"{s.name}-"
            clash = sorted(n for n in names if n.startswith(prefix) and n[len(prefix) :].isdigit())
            if clash:
                raise InputError(
                    f"{field_}.name",
                    f"its particles are named {s.name}-1, {s.name}-2, ...; a ball is already "
                    f"called {clash[0]!r}",
                )

    @property
    def incline(self):
        """The plate in its frame (tailbeam.physics.incline.InclinedPlate)."""
        return InclinedPlate(self.plate, self.inclination, self.gravity)

    @functools.cached_property
    def particles(self) -> tuple:
        """Every body of the scene as a ``Particle`` (tailbeam.streams.generator): the balls
        first (stream "", released at 0 s), then the streams' particles released before
        ``duration``, in release order. Stream particles are generated on first use
        (deterministic from the seeds)."""
        out = [
            Particle.from_ball(b, label) for b, label in zip(self.balls, self.labels, strict=True)
        ]
        if self.streams:
            generated = particles_from_settings(self.streams, self.incline)
            out += [p for p in generated if p.t_release < self.duration]
        return tuple(out)

    def expected_particles(self) -> list[float]:
        """Expected particle count of each stream released before ``duration``:
        rate x (min(stop, duration) - start)."""
        return [s.rate * (min(s.stop, self.duration) - s.start) for s in self.streams]

    def laws(self) -> tuple[ImpactLaw, ...]:
        """The ball-plate law of each ball, in ball order: the plate rows of the balls'
        contact table (``contacts``; this view does not generate stream particles)."""
        if not self.streams:
            return self.contacts().plate_laws()
        balls = ContactTable.from_settings(self.balls, self.plate.material, self.contact)
        return balls.plate_laws()

    def contacts(self) -> ContactTable:
        """The contact table of every body (tailbeam.physics.contacts): the balls, then the
        streams' particles (``particles``, generated on first use), each with its plate row;
        ball-ball rows (eq. 5) are created when a solver asks for a pair. Built once."""
        return self._contacts

    @functools.cached_property
    def _contacts(self) -> ContactTable:
        return ContactTable.from_settings(self.particles, self.plate.material, self.contact)

    def first_ball_contact(self):
        """(j, i, t): the first pair of balls (0-based, i < j) whose horizontal paths (uniform
        lateral motion, exact on a horizontal frictionless plate) come within the sum of their
        radii at t <= duration s, or None when no two balls can touch."""
        for j, b in enumerate(self.balls):
            for i, a in enumerate(self.balls[:j]):
                dx = b.position[0] - a.position[0]
                dy = b.position[1] - a.position[1]
                ux = b.velocity[0] - a.velocity[0]
                uy = b.velocity[1] - a.velocity[1]
                t = _first_approach(dx, dy, ux, uy, a.radius + b.radius, self.duration)
                if t is not None:
                    return j, i, t
        return None

    @functools.cached_property
    def needs_stream_solver(self) -> bool:
        """Streams, an inclination or balls that may touch each other: the stream solver
        (tailbeam.simulation; on the modal plate its contact forces then drive the plate one
        way); otherwise the single-ball solvers are exact and used."""
        return bool(self.streams) or self.inclination != 0.0 or bool(self.first_ball_contact())


def check_no_ball_contact(balls, duration: float) -> None:
    """On the modal plate ball-ball contact is not modelled yet: refuse (InputError naming
    ``balls[j].position``) two balls whose horizontal paths come within the sum of their
    radii by ``duration`` s. (The rigid plate runs such scenes with the stream solver.)"""
    found = Scene(balls, duration=duration).first_ball_contact() if len(balls) > 1 else None
    if found is None:
        return
    j, i, t = found
    a, b = balls[i], balls[j]
    raise InputError(
        f"balls[{j + 1}].position",
        f"ball {b.name!r} comes closer (horizontally) than the sum of the radii, "
        f"{a.radius + b.radius:.4g} m, to ball {a.name!r} at t = {t:.4g} s, so they could "
        "touch; ball-ball contact on the modal plate is not modelled yet (plate.model = "
        "'rigid' runs it)",
    )


def _first_approach(dx, dy, ux, uy, reach, duration):
    """First t in [0, duration] with |(dx, dy) + (ux, uy) t| <= reach (None if never)."""
    c = dx * dx + dy * dy - reach * reach
    if c < 0.0:
        return 0.0
    a = ux * ux + uy * uy
    b = dx * ux + dy * uy
    disc = b * b - a * c
    if a == 0.0 or b >= 0.0 or disc < 0.0:
        return None  # not approaching, or passing wide
    t = (-b - math.sqrt(disc)) / a
    return t if t <= duration else None
