"""The stream's modal band against particle size: one impact on the reference scene's plate.

    python benchmarks/bench_stream_band_size.py [--out DIR] [--speed M_S]

One coal or sandstone ball (radius 10-40 mm) lands at ``--speed`` (default 3.0 m/s, the
normal speed of a lump released 0.3-0.8 m above the 30-degree plate is 2.3-3.7 m/s) on the
reference scene's plate (examples/caving_stream.toml: SSSS, 30 degrees, damping 300 N s/m,
residual flexibility on) at (0.05, 0.07) m, through the stream solver, with the band at 10,
20 and 40 kHz (FE bases, cached after the first run). The plate is at rest: this is the band's
own effect on one contact, without the stream's chaos (docs/streams.md). Reports the peak
force, contact duration and rebound speed at 10 and 20 kHz relative to 40 kHz, beside the
a-priori estimate the stream's band check gives at 10 kHz (tailbeam.solvers.coupled.auto:
an upper estimate) and the band it would ask for. Writes DIR/band_size.csv and DIR/table.md.
"""

import argparse
import csv
from pathlib import Path

import tailbeam
from tailbeam.io.scene_file import loads_scene
from tailbeam.solvers.coupled.auto import contact_band, force_error_estimate, impact_pulse

BANDS = (10000.0, 20000.0, 40000.0)
SCENE = """
duration = 0.004
[contact]
damping = 300.0
penetration = 1e-4
[plate]
model = "modal"
boundary = "SSSS"
inclination = 30.0
fmax = {fmax!r}
[[balls]]
name = "lump"
material = "{material}"
radius = {radius!r}
position = [0.05, 0.07, {z!r}]
velocity = [0.0, 0.0, {vz!r}]
"""


def impact(material: str, radius: float, speed: float, fmax: float):
    """(peak force N, duration s, v_out m/s) of the ball's first plate contact."""
    text = SCENE.format(fmax=fmax, material=material, radius=radius, z=radius + 1e-4, vz=-speed)
    result = tailbeam.simulate(loads_scene(text), progress=False)
    rec = next(c for c in result.contacts if c.partner == "plate")
    return rec.peak_force, rec.t_end - rec.t_start, rec.v_out


def estimate(scene, speed: float) -> tuple[float, float]:
    """(upper estimate of the 10 kHz peak-force error, band for 0.5 %) of the band check for
    the scene's ball landing at ``speed`` m/s."""
    ball = scene.balls[0]
    pulse = impact_pulse(ball.mass, speed, scene.contacts().law(ball.name, "plate"))
    return force_error_estimate(scene.plate, 1e4, pulse), contact_band(scene.plate, pulse)


def row(material: str, radius: float, speed: float) -> dict:
    runs = {f: impact(material, radius, speed, f) for f in BANDS}
    top = runs[BANDS[-1]]
    scene = loads_scene(SCENE.format(fmax=1e4, material=material, radius=radius, z=1.0, vz=0.0))
    est, need = estimate(scene, speed)
    rel = {f: [a / b - 1.0 for a, b in zip(runs[f], top, strict=True)] for f in BANDS[:-1]}
    return {
        "material": material, "radius_mm": radius * 1e3, "duration_us": top[1] * 1e6,
        "peak_10k": rel[1e4][0], "peak_20k": rel[2e4][0], "duration_10k": rel[1e4][1],
        "v_out_10k": rel[1e4][2], "estimate_10k": est, "band_for_0.5pct_hz": need,
    }  # fmt: skip


def main(out_dir: Path, speed: float) -> None:
    out_dir.mkdir(parents=True, exist_ok=True)
    rows = []
    for material in ("coal", "sandstone"):
        for radius in (0.010, 0.015, 0.020, 0.030, 0.040):
            rows.append(row(material, radius, speed))
            print(rows[-1], flush=True)
    with (out_dir / "band_size.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    lines = [
        "| material | radius (mm) | contact (us, 40 kHz) | peak force 10 vs 40 kHz | 20 vs "
        "40 kHz | duration 10 vs 40 | v_out 10 vs 40 | band check's estimate at 10 kHz "
        "(upper) | band it asks for 0.5 % (kHz) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['material']} | {r['radius_mm']:g} | {r['duration_us']:.0f} | "
            f"{r['peak_10k']:+.1e} | {r['peak_20k']:+.1e} | {r['duration_10k']:+.1e} | "
            f"{r['v_out_10k']:+.1e} | {r['estimate_10k']:.1e} | "
            f"{r['band_for_0.5pct_hz'] / 1e3:.1f} |"
        )
    (out_dir / "table.md").write_text(f"speed {speed:g} m/s\n\n" + "\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default="out/bench_stream_band_size")
    ap.add_argument("--speed", type=float, default=3.0)
    args = ap.parse_args()
    main(Path(args.out), args.speed)
