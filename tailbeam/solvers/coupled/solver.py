"""Two-way coupled impacts of balls on a modal (flexible) plate: the entry point.

``simulate_coupled`` checks its inputs and hands the run to ``tailbeam.solvers.coupled.driver``
(the event loop around the compiled kernel) or, for one-way coupling, to
``tailbeam.solvers.coupled.oneway``.
"""

from tailbeam.errors import InputError, require_positive
from tailbeam.physics.bodies import STANDARD_GRAVITY, Ball, check_ball_above_plate
from tailbeam.physics.contacts import contact_table
from tailbeam.plate.basis import DEFAULT_DAMPING_RATIO, ModalBasis, modal_damping
from tailbeam.results.result import Result
from tailbeam.solvers.coupled.driver import CoupledRun
from tailbeam.solvers.coupled.oneway import simulate_one_way

DEFAULT_REST_SPEED = 0.01  # m/s, the rigid solver's value, so both models stop alike
DEFAULT_STEPS_PER_CONTACT = 200  # steps per Hertz contact duration: ~1e-5 relative error


def simulate_coupled(
    balls,
    basis: ModalBasis,
    laws,
    duration: float,
    *,
    sensors=(),
    damping_ratio: float = DEFAULT_DAMPING_RATIO,
    rayleigh=None,
    residual_flexibility: bool = True,
    coupling: str = "two-way",
    steps_per_contact: int = DEFAULT_STEPS_PER_CONTACT,
    rest_speed: float = DEFAULT_REST_SPEED,
    rest_contact_factor: float = 50.0,
    gravity: float = STANDARD_GRAVITY,
    max_steps: int = 5_000_000,
    max_events: int = 200_000,
    labels=(),
    info=None,
) -> Result:
    """Balls striking the modal plate ``basis`` over [0, duration] s; see the package docstring.

    laws: the balls' ``ContactTable`` (``Scene.contacts()``, tailbeam.physics.contacts) or
    one ball-plate ImpactLaw per ball. sensors: SensorSpec accelerometers. Damping: a
    ratio per mode (or Rayleigh (alpha 1/s, beta s)). residual_flexibility adds the static
    compliance of the truncated modes in series with each contact. steps_per_contact: steps per
    Hertz contact duration (accuracy, 2nd order). A ball whose rebound is slower than
    ``rest_speed`` (m/s), or that stays in contact longer than rest_contact_factor Hertz
    durations, is declared at rest and then loads the plate with its weight. labels: coal /
    gangue per ball (empty: from the material); info: more entries for ``Result.info``.
    Returns a ``tailbeam.Result`` with the balls' states and the plate's replay.
    """
    balls = tuple(balls)
    laws = _check_inputs(balls, basis, laws, sensors, residual_flexibility, coupling,
                         steps_per_contact)  # fmt: skip
    duration = require_positive("duration", duration)
    if coupling == "one-way":
        return simulate_one_way(
            balls,
            basis,
            laws,
            duration,
            sensors=sensors,
            damping_ratio=damping_ratio,
            rayleigh=rayleigh,
            rest_speed=rest_speed,
            gravity=gravity,
            labels=labels,
            info=info,
        )
    run = CoupledRun(
        balls,
        basis,
        laws,
        duration,
        sensors=sensors,
        zeta=modal_damping(basis.omega, damping_ratio, rayleigh),
        residual_flexibility=residual_flexibility,
        steps_per_contact=steps_per_contact,
        rest_speed=rest_speed,
        rest_contact_factor=rest_contact_factor,
        gravity=gravity,
        labels=labels,
        info=info,
    )
    return run.solve(max_steps, max_events)


def _check_inputs(balls, basis, laws, sensors, residual_flexibility, coupling, steps_per_contact):
    """InputError (one line, naming the setting) for what simulate_coupled cannot run;
    returns the balls' contact table (``laws`` as a ``ContactTable``)."""
    if not balls:
        raise InputError("balls", "need at least one ball")
    for ball in balls:
        if not isinstance(ball, Ball):
            raise InputError("balls", "must be Ball objects")
        check_ball_above_plate(ball)
    contacts = contact_table(balls, laws)
    if coupling not in ("two-way", "one-way"):
        raise InputError("plate.coupling", f"must be 'two-way' or 'one-way', got {coupling!r}")
    if int(steps_per_contact) < 4:
        raise InputError("steps_per_contact", "must be >= 4")
    for spec in sensors:
        if len(spec.position) == 2 and not basis.plate.contains(*spec.position):
            raise InputError(f"sensors[{spec.name}].position", "must lie on the plate")
    if residual_flexibility and basis.static_compliance_at is None and coupling == "two-way":
        raise InputError(
            "plate.residual_flexibility",
            f"the {basis.theory} {basis.boundary} basis has no static compliance (a plate with "
            "rigid-body modes); set plate.residual_flexibility = false",
        )
    return contacts
