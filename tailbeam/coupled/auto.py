"""Model only what the scene needs: the modal band, then the run, from a Scene.

Band. Two things need modes: the contacts and the sensors.
- A contact of duration T (Hertz estimate at the largest impact speed the ball can reach,
  tailbeam.hertz) is a pulse whose spectrum falls like 1/((2 f T)^2 - 1) above 1/T (half-sine
  envelope). Modes above ``CONTACT_BAND_FACTOR`` / T_min are driven less than ~0.6 % as hard
  as the low ones; they still matter locally as compliance, which the residual flexibility adds.
- A sensor sees modes up to its bandwidth.
fmax = max(CONTACT_BAND_FACTOR / T_min, max sensor bandwidth). The user's [plate] fmax overrides.
Theory: tailbeam.plate.compute_modes(theory="auto") picks Kirchhoff or Mindlin from the band.
The estimated truncation error is reported in ``result.info["band"]``.
"""

import math

from tailbeam.bodies import STANDARD_GRAVITY
from tailbeam.coupled.solver import simulate_coupled
from tailbeam.errors import InputError
from tailbeam.hertz import hertz_contact_duration
from tailbeam.scene import ModalPlateSettings, Scene
from tailbeam.sensor import resolve

CONTACT_BAND_FACTOR = 6.0  # fmax >= 6 / T_contact (measured: 1e-4 error with residual)


def contact_durations(scene: Scene, gravity: float = STANDARD_GRAVITY) -> dict:
    """Hertz contact duration (s) of each ball's hardest impact: the speed after falling from
    its start, sqrt(vz^2 + 2 g gap); elastic rebounds never exceed it."""
    out = {}
    for ball, law in zip(scene.balls, scene.laws(), strict=True):
        speed = math.sqrt(ball.velocity[2] ** 2 + 2 * gravity * max(ball.gap, 0.0))
        speed = max(speed, 1e-3)
        out[ball.name] = hertz_contact_duration(ball.mass, speed, law.stiffness, law.exponent)
    return out


def choose_band(scene: Scene, settings: ModalPlateSettings | None = None) -> dict:
    """The modal band for ``scene``: fmax (Hz) with the reasons and the estimated errors."""
    settings = settings or scene.modal or ModalPlateSettings()
    durations = contact_durations(scene, scene.gravity)
    t_min = min(durations.values())
    f_contact = CONTACT_BAND_FACTOR / t_min
    f_sensor = max((resolve(s).bandwidth_hz for s in scene.sensors), default=0.0)
    chosen = max(f_contact, f_sensor)
    fmax = settings.fmax_hz if settings.fmax_hz is not None else chosen
    x = 2.0 * fmax * t_min
    level = 1.0 / (x * x - 1.0) if x > 1.0 else 1.0
    return {
        "fmax_hz": fmax,
        "user_fmax": settings.fmax_hz is not None,
        "contact_duration_min_s": t_min,
        "fmax_contact_hz": f_contact,
        "fmax_sensors_hz": f_sensor,
        # relative force-spectrum level at fmax: how hard the first left-out mode is driven
        "truncation_force_level": level,
        "sensor_band_covered": fmax >= f_sensor,
    }


def build_basis(scene: Scene, band: dict | None = None, *, use_cache: bool = True):
    """The modal basis of the scene's plate (tailbeam.plate.compute_modes) for the band."""
    settings = scene.modal or ModalPlateSettings()
    band = band or choose_band(scene, settings)
    from tailbeam.plate import compute_modes

    return compute_modes(
        scene.plate,
        settings.boundary,
        theory=settings.theory,
        fmax_hz=band["fmax_hz"],
        divisions=settings.mesh_divisions,
        use_cache=use_cache,
    )


def simulate_scene_modal(scene: Scene, *, basis=None, use_cache: bool = True, **options):
    """Run a scene on the modal plate: choose the band, build (or take) the basis, simulate.

    ``options`` go to simulate_coupled (e.g. steps_per_contact). The band and the basis's
    description are in result.info["band"] and result.info["basis"]."""
    if not isinstance(scene, Scene):
        raise InputError("scene", "must be a tailbeam.scene.Scene")
    settings = scene.modal or ModalPlateSettings()
    band = choose_band(scene, settings)
    if basis is None:
        basis = build_basis(scene, band, use_cache=use_cache)
    result = simulate_coupled(
        scene.balls,
        basis,
        scene.laws(),
        scene.duration,
        sensors=scene.sensors,
        damping_ratio=settings.damping_ratio,
        rayleigh=settings.rayleigh,
        residual_flexibility=settings.residual_flexibility,
        coupling=settings.coupling,
        gravity=scene.gravity,
        **options,
    )
    result.info["band"] = band
    result.info["basis"] = {
        "theory": basis.theory,
        "boundary": basis.boundary,
        "n_modes": basis.n_modes,
        "top_frequency_hz": float(basis.frequencies_hz[-1]),
        **{k: v for k, v in basis.info.items() if isinstance(v, (str, int, float, bool))},
    }
    return result
