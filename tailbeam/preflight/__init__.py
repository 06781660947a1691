"""Checks of a whole scene before any work starts: the contact law is used where it is valid,
and the outputs fit in memory and on disk.

Each check raises InputError naming the scene key to change (``contact.exponent``,
``balls[2].velocity``, ``sensors[1].sample_rate``) and the rule, so a scene that would crash,
hang or allocate without bound is refused in milliseconds, before the solver starts.

Rules (and why):
- Penetration: the undamped (upper-bound) maximum penetration of every ball's hardest impact
  (speed after falling from its start, tailbeam.physics.hertz) must stay below
  ``MAX_PENETRATION_FRACTION`` of its radius. Hertz theory, which gives k, assumes small
  deformation; far beyond that the law is used outside its validity (an exponent of 1e6
  makes the force vanish below 1 m of penetration).
- Damping: the contact damping ratio c / (2 sqrt(k_d m)) with the contact stiffness
  k_d = e k d^(e-1) at the end of the STEP ramp must stay below ``MAX_CONTACT_DAMPING_RATIO``.
  Measured for coal on steel at 1 m/s: restitution 0.11 at a ratio of 2.8, 0.016 at 28 and
  0 at 280 (the impact ends at rest inside the contact); larger values change nothing
  physical and only drive the contact integrator's step below machine resolution (1e300
  ended in "step size underflow").
- Magnitudes (``tailbeam.preflight.magnitudes``): values a unit slip makes 1000 times too
  large or too small (a 30 m ball, 2000 m/s) are refused with the unit probably meant.
- Overlaps (``tailbeam.preflight.overlaps``): bodies may touch at release but not overlap
  (ball-ball, stream particles against balls), found with k-d trees in O(n log n).
- Output size: timeseries.csv rows x columns and every sensor's samples are bounded
  (``MAX_TIMESERIES_VALUES``, ``MAX_SENSOR_SAMPLES``); a sensor needs ``MIN_SENSOR_SAMPLES``
  over the duration for a spectrum.
"""

import math

from tailbeam.errors import InputError, WorkLimitError
from tailbeam.physics.contacts import PLATE
from tailbeam.physics.hertz import hertz_max_penetration

MAX_PENETRATION_FRACTION = 0.1  # of the ball radius
MAX_PARTICLES = 200_000  # per scene: memory ~40 kB per particle (records, force histories)
MAX_CONTACT_DAMPING_RATIO = 1e4
MAX_TIMESERIES_VALUES = 20_000_000  # ~300 MB of CSV
MAX_SENSOR_SAMPLES = 20_000_000  # per sensor; the chain works on a grid 2-4x finer
MIN_SENSOR_SAMPLES = 16


def impact_speed(ball, gravity: float) -> float:
    """Largest speed (m/s) the ball can reach the plate with: sqrt(vz^2 + 2 g gap)."""
    return math.sqrt(ball.velocity[2] ** 2 + 2.0 * gravity * max(ball.gap, 0.0))


def check_contacts(scene) -> None:
    """Penetration and damping rules (module docstring) for every ball of ``scene``."""
    for i, (ball, law) in enumerate(zip(scene.balls, scene.laws(), strict=True), start=1):
        check_ball_contact(ball, law, scene.gravity, f"balls[{i}].velocity")


def check_ball_contact(ball, law, gravity: float, field: str) -> None:
    """Penetration and damping rules for one ball with its ball-plate ``law``; ``field``
    is named when its speed is to blame."""
    speed = impact_speed(ball, gravity)
    if speed > 0.0:
        _check_penetration(field, ball, law, speed)
    k_d = law.exponent * law.stiffness * law.penetration ** (law.exponent - 1.0)
    ratio = law.damping / (2.0 * math.sqrt(k_d * ball.mass))
    if ratio > MAX_CONTACT_DAMPING_RATIO:
        limit = MAX_CONTACT_DAMPING_RATIO * 2.0 * math.sqrt(k_d * ball.mass)
        raise InputError(
            "contact.damping",
            f"{law.damping:.3g} N s/m gives ball {ball.name!r} a contact damping ratio "
            f"of {ratio:.3g}; it must be <= {MAX_CONTACT_DAMPING_RATIO:g} "
            f"(c <= {limit:.3g} N s/m here; impacts end at rest from a ratio of ~300)",
        )


def _check_penetration(field, ball, law, speed) -> None:
    depth = hertz_max_penetration(ball.mass, speed, law.stiffness, law.exponent)
    allowed = MAX_PENETRATION_FRACTION * ball.radius
    if depth <= allowed:
        return
    field = "contact.exponent" if law.exponent != 1.5 else field
    raise InputError(
        field,
        f"ball {ball.name!r} would penetrate the plate by {depth:.3g} m at {speed:.3g} m/s "
        f"with exponent {law.exponent:g}, more than {MAX_PENETRATION_FRACTION:g} of its radius "
        f"({allowed:.3g} m): the Hertz contact law is valid for small deformation only",
    )


def check_outputs(scene) -> None:
    """Size rules for timeseries.csv and the sensors (module docstring)."""
    rows = math.floor(scene.duration * scene.sample_rate) + 1
    values = rows * (1 + 3 * len(scene.balls))
    if values > MAX_TIMESERIES_VALUES and not scene.needs_stream_solver:  # (none for streams)
        raise InputError(
            "sample_rate",
            f"timeseries.csv would hold {rows:.3g} rows x {1 + 3 * len(scene.balls)} columns "
            f"({values:.3g} values, limit {MAX_TIMESERIES_VALUES:.3g}); lower sample_rate or "
            "duration",
        )
    for i, sensor in enumerate(scene.sensors, start=1):
        n = scene.duration * sensor.sample_rate
        field = f"sensors[{i}].sample_rate"
        if n > MAX_SENSOR_SAMPLES:
            raise InputError(
                field,
                f"{sensor.sample_rate:g} Hz over {scene.duration:g} s is {n:.3g} samples, limit "
                f"{MAX_SENSOR_SAMPLES:.3g}; lower it or the duration",
            )
        if n < MIN_SENSOR_SAMPLES:
            raise InputError(
                field,
                f"{sensor.sample_rate:g} Hz over {scene.duration:g} s gives {n:.3g} samples; a "
                f"signal and its spectrum need at least {MIN_SENSOR_SAMPLES}",
            )


def check_streams(scene, max_particles: int | None = MAX_PARTICLES,
                  solver: str = "fast stream solver") -> None:  # fmt: skip
    """Rules for a scene a stream solver runs (streams, an inclined plate or balls that may
    touch; the caller decides): the particle count the ``solver`` accepts (``max_particles``,
    None: no limit), from the expected count before the particles are generated and the
    actual count after; then the contact rules for every stream particle
    (``streams[i].height`` or ``.velocity``, whichever gives more speed). WorkLimitError
    names the setting to change."""
    _check_particle_count(scene, max_particles, solver, sum(scene.expected_particles()), "expects")
    _check_particle_count(scene, max_particles, solver, len(scene.particles) - len(scene.balls),
                          "has")  # fmt: skip
    streams = {s.name: i for i, s in enumerate(scene.streams, start=1)}
    g_n = scene.gravity * math.cos(math.radians(scene.inclination))
    contacts, first = scene.contacts(), len(scene.balls)
    for k, p in enumerate(scene.particles[first:], start=first):
        ball = p.ball()
        law = contacts.law(k, PLATE)
        key = "velocity" if ball.velocity[2] ** 2 > 2.0 * g_n * ball.gap else "height"
        check_ball_contact(ball, law, g_n, f"streams[{streams[p.stream]}].{key}")


def _check_particle_count(scene, max_particles, solver, from_streams: float, verb: str) -> None:
    n = len(scene.balls) + from_streams
    if max_particles is None or n <= max_particles:
        return
    if scene.streams:
        expected = scene.expected_particles()
        k = max(range(len(expected)), key=expected.__getitem__)
        field = f"streams[{k + 1}].rate"
    else:
        field = "balls"
    raise WorkLimitError(
        f"{field}: the scene {verb} {n:.4g} particles; the {solver} accepts at most "
        f"{max_particles} (ball-ball contact, streams and inclined plates need the fast "
        "stream solver beyond that): lower the rate, shorten the streams or the duration"
    )


def check_scene(scene) -> None:
    """Every preflight rule; raises InputError (or WorkLimitError) on the first broken one."""
    from tailbeam.preflight.magnitudes import check_magnitudes
    from tailbeam.preflight.overlaps import check_ball_pairs, check_particles_against_balls

    check_magnitudes(scene)
    check_ball_pairs(scene.balls)
    check_contacts(scene)
    check_outputs(scene)
    if scene.needs_stream_solver:
        check_streams(scene)
    if scene.streams:
        check_particles_against_balls(scene)
