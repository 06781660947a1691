"""Random scenes drawn from the documented ranges (docs/scene-files.md), for the property
tests and ``benchmarks/fuzz_scenes.py``.

``draw_scene(seed, size)`` gives a scene table (the TOML keys) from a seed: balls on a grid
of cells so no two overlap, over a rigid or modal plate, horizontal or inclined, with or
without a small stream and sensors. ``size`` scales the work: "small" keeps each scene to
seconds (CI), "full" reaches the ranges' far ends (more balls, longer runs, wider bands).
"""

import numpy as np

MATERIALS = ("coal", "sandstone", "carbon_steel")
BOUNDARIES = ("SSSS", "CCCC", "CSCS", "CFFF", "SSSF")
SIZES = {
    # balls, duration (s), modal bands (Hz), stream particles, sensor rates (Hz)
    "small": (3, 0.03, (1500.0, 3000.0), 6, (8000.0, 12800.0)),
    "full": (12, 0.3, (1500.0, 3000.0, 5000.0, 10000.0), 60, (8000.0, 25600.0, 51200.0)),
}


def _balls(rng, n, side, incline):
    """n balls in distinct cells of a grid over the plate, each clear of its cell's edges."""
    cells = int(np.ceil(np.sqrt(max(n, 1)))) + 1
    pitch = 0.8 * side / cells
    picks = rng.choice(cells * cells, size=n, replace=False)
    balls = []
    for k, c in enumerate(picks):
        r = float(rng.uniform(0.005, min(0.04, 0.45 * pitch)))
        x = -0.4 * side + (c % cells + 0.5) * pitch
        y = -0.4 * side + (c // cells + 0.5) * pitch
        z = r + float(rng.choice([0.0, rng.uniform(1e-4, 0.05)]))
        v = [float(rng.normal(0, 0.5)), float(rng.normal(0, 0.5)), -float(rng.uniform(0, 5))]
        if incline:
            v[0] = float(rng.uniform(-0.5, 1.0))
        balls.append(
            {
                "name": f"b{k}",
                "material": str(rng.choice(MATERIALS)),
                "radius": r,
                "position": [x, y, z],
                "velocity": v,
            }
        )
    return balls


def _stream(rng, n, duration):
    stop = float(rng.uniform(0.2, 0.6)) * duration
    return {
        "name": "s",
        "rate": n / stop,
        "start": 0.0,
        "stop": stop,
        "gangue_fraction": float(rng.uniform(0, 1)),
        "radius": [0.005, float(rng.uniform(0.006, 0.03))],
        "area": [[-0.25, -0.05], [-0.2, 0.2]],
        "height": [0.01, 0.05],
        "velocity": [0.2, 0.0, -0.5],
        "velocity_spread": 0.1,
        "seed": int(rng.integers(0, 1000)),
    }


def _sensors(rng, n, rates):
    return [
        {
            "name": f"S{k}",
            "position": [float(rng.uniform(-0.25, 0.25)), float(rng.uniform(-0.25, 0.25))],
            "sample_rate": float(rng.choice(rates)),
        }
        for k in range(n)
    ]


def draw_scene(seed: int, size: str = "small") -> dict:
    """A valid scene table from ``seed`` (module docstring)."""
    n_balls, duration_max, bands, n_stream, rates = SIZES[size]
    rng = np.random.default_rng(seed)
    modal = bool(rng.integers(0, 2))
    incline = float(rng.choice([0.0, rng.uniform(5.0, 40.0)]))
    duration = float(rng.uniform(0.2, 1.0)) * duration_max
    plate = {"model": "modal" if modal else "rigid"}
    if incline:
        plate["inclination"] = incline
    if modal:
        plate.update(boundary=str(rng.choice(BOUNDARIES)), fmax=float(rng.choice(bands)))
    scene = {"duration": duration, "sample_rate": 2000.0, "plate": plate}
    stream = bool(rng.integers(0, 2)) and n_stream > 0
    scene["balls"] = _balls(rng, int(rng.integers(0 if stream else 1, n_balls + 1)), 0.6, incline)
    if not scene["balls"]:
        del scene["balls"]
    if stream:
        scene["streams"] = [_stream(rng, int(rng.integers(1, n_stream + 1)), duration)]
    if modal and rng.integers(0, 2):
        scene["sensors"] = _sensors(rng, int(rng.integers(1, 3)), rates)
    return scene
