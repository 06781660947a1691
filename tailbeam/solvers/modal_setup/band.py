"""The modal band a scene needs, and the peak-force error the band leaves at its contacts.

Band. Two outputs need modes: the sensor signals and the contact forces.
- A sensor cannot see above its bandwidth: the band reaches the largest sensor bandwidth.
- A contact is softened by the modes left out only through their compliance, which the
  residual flexibility adds quasi-statically; what it misses is their dynamic excess. The
  contact's force pulse F(t) is computed once per ball on a rigid plate (the IMPACT law with
  its damping, at the hardest impact speed the ball can reach; scipy, ~10 ms): its RMS
  angular frequency Omega = sqrt(int F'^2 / int F^2) (pi/T for a half-sine; the damping
  ramp over the penetration d sharpens small balls' pulses up to 1.7x), and its secant
  compliance C_c = delta / F at the force peak. A mode of frequency f responds with a dynamic
  excess 1/(u^2 - 1), u = 2 pi f / Omega, over its static F/omega^2, so treating every mode
  above fc quasi-statically misses C_res(fc) g(u_c) of compliance,
  g(u) = (u/2) ln((u+1)/(u-1)) - 1 ~ 1/(3 u^2) (the 1/f^2 weight of the modal sum over a
  plate's near-constant modal density). C_res(fc), the static compliance of the modes above
  fc at a point, is the infinite thin plate's 1 / (8 pi^2 fc sqrt(rho h D)) (within 5 % of the
  SSSS closed form, tests/test_band.py). Energy balance at the peak (E = F delta/(e+1) +
  C F^2/2) turns a compliance error dC into a peak-force error (e/2) dC / C_c:
      force error(fc) ~ BAND_SAFETY (e/2) C_res(fc) g(u_c) / C_c
  The model is crude (the onset of a damped pulse excites high modes more than its RMS
  frequency says), so BAND_SAFETY is calibrated: on exact SSSS modes (independent of the FE
  model) measured / estimate was 0.04-0.85 for 5-40 mm coal and sandstone at 0.5-6 m/s with
  and without contact damping, bands 1/T to 4/T (tests/test_band.py checks four of them); on
  the FE Mindlin plate of the 30-ball scene see benchmarks/bench_band.py.
  The contacts need the smallest fc >= 1/T with force error <= ``BAND_ACCURACY``. Without
  residual flexibility the modes above fc are missing: error ~ BAND_SAFETY (e/2) C_res / C_c.
fmax = max(sensor bandwidth, contact band), rounded up to a multiple of BAND_GRID_HZ so that
small edits of a scene reuse the cached basis. The user's [plate] fmax overrides.

The sensors (result.info["band"]["sensor_note"]): with fmax at the bandwidth every mode a
sensor can see is kept; the modes above fmax reach a sensor only through their quasi-static
response, which the mode-acceleration correction adds at each sensor when residual
flexibility is on (``ModalReplay.sample``, docs/fe-convergence.md).

Cost. Before anything is assembled the basis's DOFs, modes, memory and time are estimated
(tailbeam.plate.fe.cost) and a band over the limits is refused naming ``plate.fmax``.
Theory and mesh: tailbeam.plate.compute_modes(theory="auto") picks them from the band.
"""

import functools
import math

import numpy as np

from tailbeam.physics.bodies import STANDARD_GRAVITY
from tailbeam.physics.contact_law import impact_force, impact_force_scalar
from tailbeam.physics.hertz import hertz_contact_duration
from tailbeam.plate.contact_tail import TAIL_BAND_FACTOR, TAIL_MAX_HZ
from tailbeam.scene import ModalPlateSettings, Scene
from tailbeam.signals.sensor import resolve

BAND_ACCURACY = 5e-3  # target peak-force error from the band: half the outputs' 1 %
BAND_SAFETY = 20.0  # on the force-error estimate (calibrated, see the module docstring)
BAND_GRID_HZ = 500.0  # the automatic fmax is rounded up to a multiple of this (cache reuse)
PULSE_SAMPLES = 1000  # samples of the rigid-plate force pulse for its RMS frequency
MIN_CONTACT_BAND_FACTOR = 1.0  # fc >= 1 / T: modes below 1/T respond dynamically
STREAM_MIN_BAND_HZ = 10_000.0  # a stream scene's band without sensors or plate.fmax


def contact_durations(scene: Scene, gravity: float = STANDARD_GRAVITY) -> dict:
    """Hertz contact duration (s) of each ball's hardest impact: the speed after falling from
    its start, sqrt(vz^2 + 2 g gap); elastic rebounds never exceed it."""
    return {name: c["duration_s"] for name, c in _contacts(scene, gravity).items()}


def _contacts(scene: Scene, gravity: float = STANDARD_GRAVITY) -> dict:
    """Per ball's hardest impact (the speed after falling from its start, sqrt(vz^2 + 2 g
    gap); rebounds never exceed it): impact_pulse of it, plus the speed (m/s)."""
    out = {}
    for ball, law in zip(scene.balls, scene.laws(), strict=True):
        speed = max(math.sqrt(ball.velocity[2] ** 2 + 2 * gravity * max(ball.gap, 0.0)), 1e-3)
        out[ball.name] = {"speed_m_s": speed, **impact_pulse(ball.mass, speed, law)}
    return out


def stream_band_estimate(scene: Scene, fmax: float, residual: bool = True) -> dict:
    """The band's estimated peak-force error for a stream scene's plate contacts, as
    ``choose_band`` estimates a single ball's: per material, the particle with the shortest
    Hertz contact at the largest normal speed it can reach (sqrt(vz^2 + 2 g cos(theta) gap),
    plate frame), its force pulse, ``force_error_estimate`` at ``fmax`` (Hz) and the band
    ``contact_band`` would need. Keys: truncation_force_error, hardest_contact,
    contact_duration_min_s, fmax_contact_hz ({} without particles)."""
    table, g_n = scene.contacts(), scene.gravity * math.cos(math.radians(scene.inclination))
    shortest = {}  # material -> (duration, particle, speed, law)
    for p in scene.particles:
        law = table.law(p.name, "plate")
        gap = p.position[2] - p.radius
        speed = max(math.sqrt(p.velocity[2] ** 2 + 2.0 * g_n * max(gap, 0.0)), 1e-3)
        duration = hertz_contact_duration(p.mass, speed, law.stiffness, law.exponent)
        if p.material.name not in shortest or duration < shortest[p.material.name][0]:
            shortest[p.material.name] = (duration, p, speed, law)
    if not shortest:
        return {}
    pulses = {p.name: impact_pulse(p.mass, v, law) for _t, p, v, law in shortest.values()}
    errors = {n: force_error_estimate(scene.plate, fmax, c, residual) for n, c in pulses.items()}
    hardest = max(errors, key=errors.get)
    return {
        "truncation_force_error": float(errors[hardest]),
        "hardest_contact": hardest,
        "contact_duration_min_s": float(min(t for t, *_ in shortest.values())),
        "fmax_contact_hz": float(
            max(contact_band(scene.plate, c, residual=residual) for c in pulses.values())
        ),
    }


def impact_pulse(mass: float, speed: float, law) -> dict:
    """``rigid_pulse`` (a copy: the same impact is computed once per process, as the band
    and the run's cost estimate both ask for it)."""
    return dict(rigid_pulse(float(mass), float(speed), law))


@functools.lru_cache(maxsize=4096)
def rigid_pulse(mass: float, speed: float, law) -> dict:
    """Force pulse of a ball of ``mass`` (kg) striking a rigid flat at ``speed`` (m/s) under
    the IMPACT ``law``, without gravity: duration_s (s), compliance_m_n = penetration / force
    at the force peak (m/N), pulse_omega = sqrt(int F'^2 dt / int F^2 dt) (rad/s), exponent,
    restitution (rebound speed / ``speed``: 0 when the impact ends at rest)."""
    from scipy.integrate import solve_ivp

    t_hertz = hertz_contact_duration(mass, speed, law.stiffness, law.exponent)

    def force(d, dd):
        args = (law.stiffness, law.exponent, law.damping, law.penetration, law.clamp)
        return impact_force_scalar(d, dd, *args)

    def leave(t, y):  # penetration back to zero, or (clamped law) the force back to zero
        return 1.0 if t < 1e-3 * t_hertz else min(y[0], force(y[0], y[1]) + 1e-300)

    leave.terminal, leave.direction = True, -1
    sol = solve_ivp(
        lambda t, y: (y[1], -force(y[0], y[1]) / mass),
        (0.0, 10.0 * t_hertz),
        (0.0, speed),
        rtol=1e-7,
        atol=1e-10 * speed * t_hertz,
        max_step=t_hertz / 50.0,
        dense_output=True,
        events=leave,
    )
    t = np.linspace(0.0, sol.t[-1], PULSE_SAMPLES)
    d, dd = sol.sol(t)
    f = impact_force(d, dd, law)
    peak = int(np.argmax(f))
    slope = np.gradient(f, t)
    return {
        "duration_s": float(sol.t[-1]),
        "compliance_m_n": float(d[peak] / f[peak]),
        "pulse_omega": float(np.sqrt(np.trapezoid(slope**2, t) / np.trapezoid(f**2, t))),
        "exponent": law.exponent,
        "restitution": float(max(-sol.y[1, -1], 0.0) / speed),
    }


def residual_compliance_estimate(plate, f_cut_hz: float) -> float:
    """Static compliance (m/N) of the modes above ``f_cut_hz`` at a point: the infinite thin
    plate's 1 / (8 pi^2 f sqrt(rho h D)) (constant modal density A/2 sqrt(rho h/D), mean
    squared unit-mass shape 1/(rho h A)), without the safety factor."""
    return 1.0 / (
        8.0 * math.pi**2 * f_cut_hz * math.sqrt(plate.mass_per_area * plate.bending_stiffness)
    )


def _dynamic_fraction(u):
    """Compliance the quasi-static treatment misses, as a fraction of C_res(fc), u = fc / f_p:
    the modal sum's 1/f^2 weight times each mode's dynamic excess 1/(u^2 - 1) above fc,
    integrated: (u/2) ln((u+1)/(u-1)) - 1 (~ 1/(3 u^2) for large u)."""
    return 0.5 * u * math.log((u + 1.0) / (u - 1.0)) - 1.0


def force_error_estimate(plate, f_cut_hz, contact: dict, residual=True) -> float:
    """Estimated relative peak-force error of ``contact`` (an entry of _contacts) when the
    band stops at ``f_cut_hz`` (module docstring)."""
    scale = BAND_SAFETY * 0.5 * contact["exponent"] / contact["compliance_m_n"]
    c_res = residual_compliance_estimate(plate, f_cut_hz)
    if not residual:
        return scale * c_res
    u = 2.0 * math.pi * f_cut_hz / contact["pulse_omega"]
    if u <= 1.0:
        return math.inf  # the band stops below the pulse's own frequency
    return scale * c_res * _dynamic_fraction(u)


def contact_band(plate, contact: dict, accuracy=BAND_ACCURACY, residual=True) -> float:
    """Smallest band (Hz), at least MIN_CONTACT_BAND_FACTOR / T, whose force_error_estimate
    is ``accuracy`` (the estimate falls monotonically with the band)."""
    from scipy.optimize import brentq

    def excess(f):
        return force_error_estimate(plate, f, contact, residual) - accuracy

    lo = MIN_CONTACT_BAND_FACTOR / contact["duration_s"]
    if excess(lo) <= 0.0:
        return lo
    hi = 2.0 * lo
    while excess(hi) > 0.0:
        hi *= 2.0
    return brentq(excess, lo, hi, rtol=1e-6)


def choose_band(scene: Scene, settings: ModalPlateSettings | None = None) -> dict:
    """The modal band for ``scene``: fmax (Hz) with the reasons and the estimated errors."""
    settings = settings or scene.modal or ModalPlateSettings()
    residual = settings.residual_flexibility
    contacts = _contacts(scene, scene.gravity)
    needs = {name: contact_band(scene.plate, c, residual=residual) for name, c in contacts.items()}
    hardest = max(needs, key=needs.get)
    f_contact = needs[hardest]
    f_sensor = max((resolve(s).bandwidth_hz for s in scene.sensors), default=0.0)
    # on a grid, so that small edits of a scene (a ball's height or speed) reuse the cached basis
    chosen = BAND_GRID_HZ * math.ceil(max(f_contact, f_sensor) / BAND_GRID_HZ - 1e-9)
    fmax = settings.fmax_hz if settings.fmax_hz is not None else chosen
    t_min = min(c["duration_s"] for c in contacts.values())
    errors = {
        name: force_error_estimate(scene.plate, fmax, c, residual=residual)
        for name, c in contacts.items()
    }
    return {
        "fmax_hz": float(fmax),
        "user_fmax": settings.fmax_hz is not None,
        "reason": _reason(settings, f_contact, f_sensor, hardest),
        "accuracy": BAND_ACCURACY,
        "contact_duration_min_s": t_min,
        "fmax_contact_hz": float(f_contact),
        "fmax_sensors_hz": float(f_sensor),
        "hardest_contact": hardest,
        # estimated relative peak-force error from the band, worst ball
        "truncation_force_error": float(max(errors.values())),
        # kept from the earlier rule (a contract of impacts.json): the half-sine force-spectrum
        # level 1/((2 fmax T_min)^2 - 1) of the shortest contact at fmax
        "truncation_force_level": _spectrum_level(fmax, t_min),
        "sensor_band_covered": bool(fmax >= f_sensor),
        "sensor_note": (
            "modes above fmax reach the sensors quasi-statically (mode-acceleration "
            "correction, with residual flexibility on)"
        ),
    }


def _spectrum_level(fmax, t_min) -> float:
    x = 2.0 * fmax * t_min
    return float(1.0 / (x * x - 1.0)) if x > 1.0 else 1.0


def _reason(settings, f_contact, f_sensor, hardest) -> str:
    if settings.fmax_hz is not None:
        return "plate.fmax set in the scene"
    if f_sensor >= f_contact:
        return f"sensor bandwidth {f_sensor / 1e3:.1f} kHz (contacts need {f_contact / 1e3:.1f})"
    return (
        f"contact of {hardest}: {f_contact / 1e3:.1f} kHz for a peak-force error "
        f"<= {BAND_ACCURACY:g} (sensors need {f_sensor / 1e3:.1f})"
    )


def stream_band(scene) -> dict:
    """The modal band of a stream scene: plate.fmax, else the sensors' bandwidth (at least
    STREAM_MIN_BAND_HZ), and the coupling (plate.coupling: two-way by default)."""
    settings = scene.modal or ModalPlateSettings()
    f_sensor = max((resolve(s).bandwidth_hz for s in scene.sensors), default=0.0)
    fmax = settings.fmax_hz or max(f_sensor, STREAM_MIN_BAND_HZ)
    two_way = settings.coupling == "two-way"
    return {**_stream_tail(settings, fmax, two_way),
        "fmax_hz": float(fmax), "user_fmax": settings.fmax_hz is not None,
        "reason": "plate.fmax" if settings.fmax_hz else "the sensors' bandwidth",
        "sensor_band_covered": bool(fmax >= f_sensor),
        "accuracy": BAND_ACCURACY, "residual_flexibility": settings.residual_flexibility,
        "two_way": two_way,
        "coupling": (
            "two-way (the modes in the stream solver's active set; residual flexibility at "
            f"the contacts {'on' if settings.residual_flexibility else 'off'})" if two_way
            else "one-way (stream contacts on the rigid plate drive the modes)"
        ),
    }  # fmt: skip


def _stream_tail(settings, fmax: float, two_way: bool) -> dict:
    """The stream's contact tail (plate.tail, tailbeam.plate.contact_tail): with
    "ritz" or "auto" (the default), where it applies (two-way coupling, residual flexibility,
    a band below TAIL_MAX_HZ / 1.5), k oscillators per contact for the modes up to
    ``tail_band_hz`` (TAIL_BAND_FACTOR x the band, at most TAIL_MAX_HZ); else None: the
    static spring alone, for ``tail_reason``."""
    why = None
    wide = min(TAIL_BAND_FACTOR * fmax, TAIL_MAX_HZ)
    if settings.tail == "quasi-static":
        why = "plate.tail"
    elif settings.tail == "auto" and settings.mesh is not None:
        why = ("a structure from plate.mesh: its contact tails need its modes to "
               f"{TAIL_BAND_FACTOR:g}x the band, solved only with plate.tail = 'ritz'")  # fmt: skip
    elif not (two_way and settings.residual_flexibility):
        why = "one-way coupling" if not two_way else "residual flexibility off"
    elif wide < 1.5 * fmax:
        why = f"the band is within 1.5x of {TAIL_MAX_HZ / 1e3:g} kHz, where contact tails stop"
    k = settings.tail_modes_for(stream=True)
    return {
        "tail_band_hz": None if why else wide,
        "tail_oscillators": 0 if why else int(k), "tail_reason": why or "",
    }  # fmt: skip


def check_stream_band(scene, band: dict) -> str | None:
    """Add the band check of a stream scene to its ``band`` (``stream_band``; the keys of
    ``tailbeam.solvers.modal_setup.band.stream_band_estimate``); the one line to show when the
    band is below what the shortest plate contact needs, else None."""
    # with the contact tail the contacts see the modes to its band (tailbeam.solvers.stream.
    # contact_tail; its own error, measured <= 0.33 %, is not in the estimate)
    seen = band.get("tail_band_hz") or band["fmax_hz"]
    band.update(stream_band_estimate(scene, seen, band["residual_flexibility"]))
    if band.get("truncation_force_error", 0.0) > band["accuracy"]:
        return _band_warning(band)
    return None


def _band_warning(band) -> str:
    """One line: the band the stream's contacts see (its modal band, or its contact tails')
    is below what its shortest plate contact needs."""
    error = band["truncation_force_error"]
    estimate = (
        f"estimated error up to {error:.1%} (an upper estimate: measured 0.04-0.85 of it"
        if math.isfinite(error)
        else "the band stops below that contact's own frequency (no error estimate"
    )
    tails = band.get("tail_band_hz")
    tails = f", contact tails to {tails / 1e3:g} kHz" if tails else ""
    return (
        f"modal band 0-{band['fmax_hz'] / 1e3:g} kHz ({band['reason']}{tails}): the shortest plate "
        f"contacts ({band['hardest_contact']}, {band['contact_duration_min_s'] * 1e6:.0f} us) "
        f"would need {band['fmax_contact_hz'] / 1e3:.1f} kHz for a {band['accuracy']:.1%} peak "
        f"force; {estimate}; docs/streams.md, band and particle size)"
    )
