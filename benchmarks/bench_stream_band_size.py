"""The stream's modal band against particle size: one impact on the reference scene's plate.

    python benchmarks/bench_stream_band_size.py --out DIR [--speed M_S] [--quick]

Reproduces the two tables of docs/streams.md ("Band and particle size"). One coal or sandstone
ball (radius 10-40 mm) lands at ``--speed`` (default 3.0 m/s: the normal speed of a lump
released 0.3-0.8 m above the 30-degree plate is 2.3-3.7 m/s) on the reference scene's plate
(examples/caving_stream.toml: SSSS, 30 degrees, damping 300 N s/m, residual flexibility on,
the static residual spring alone) at (0.05, 0.07) m, through the stream solver, with the band
at 10, 20 and 40 kHz (FE bases, cached after the first run). The plate is at rest: this is
the band's own effect on one contact, without the stream's chaos. Baseline, in the same run:
the 40 kHz band. Reports the peak force, contact duration and rebound speed at 10 and 20 kHz
relative to 40 kHz, beside the a-priori estimate the stream's band check gives at 10 kHz
(tailbeam.solvers.modal_setup.band: an upper estimate) and the band it would ask for. Beside
them the 10 kHz band with the contact tails (``plate.tail = "ritz"``: 4 oscillators per
contact for the modes from 10 to 40 kHz, tailbeam.plate.contact_tail), against the 40 kHz
basis and against a 40 kHz basis on the 10 kHz basis' own mesh (the tails are built on that
mesh: this isolates the tail model from the meshes' difference, shown in the last column).
``--quick``: coal only, radii 10 and 30 mm.

Writes DIR/band_size.csv and DIR/table.md.
"""

import argparse
import csv
from pathlib import Path

import tailbeam
from tailbeam.io.scene_file import loads_scene
from tailbeam.solvers.modal_setup.band import contact_band, force_error_estimate, impact_pulse

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
{extra}
[[balls]]
name = "lump"
material = "{material}"
radius = {radius!r}
position = [0.05, 0.07, {z!r}]
velocity = [0.0, 0.0, {vz!r}]
"""


STATIC = 'tail = "quasi-static"'  # the static residual spring alone


def impact(material: str, radius: float, speed: float, fmax: float, extra: str = STATIC):
    """(peak force N, duration s, v_out m/s) of the ball's first plate contact; ``extra``:
    more [plate] keys (default: the static spring alone, no contact tail)."""
    text = SCENE.format(fmax=fmax, material=material, radius=radius, z=radius + 1e-4, vz=-speed,
                        extra=extra)  # fmt: skip
    result = tailbeam.simulate(loads_scene(text), progress=False)
    rec = next(c for c in result.impacts if c.partner == "plate")
    return rec.peak_force, rec.t_end - rec.t_start, rec.v_out


def estimate(scene, speed: float) -> tuple[float, float]:
    """(upper estimate of the 10 kHz peak-force error, band for 0.5 %) of the band check for
    the scene's ball landing at ``speed`` m/s."""
    ball = scene.balls[0]
    pulse = impact_pulse(ball.mass, speed, scene.contacts().law(ball.name, "plate"))
    return force_error_estimate(scene.plate, 1e4, pulse), contact_band(scene.plate, pulse)


def band_divisions() -> int:
    """Mesh divisions of the 10 kHz basis (the mesh its contact tail is built on)."""
    from tailbeam.solvers.modal_setup.setup import build_basis

    text = SCENE.format(fmax=1e4, material="coal", radius=0.01, z=1.0, vz=0.0, extra="")
    return int(build_basis(loads_scene(text), {"fmax_hz": 1e4}).info["divisions"])


def row(material: str, radius: float, speed: float, divisions: int) -> dict:
    runs = {f: impact(material, radius, speed, f) for f in BANDS}
    top = runs[BANDS[-1]]
    tail = impact(material, radius, speed, 1e4, 'tail = "ritz"')
    same = impact(material, radius, speed, 4e4, f"{STATIC}\nmesh_divisions = {divisions}")
    text = SCENE.format(fmax=1e4, material=material, radius=radius, z=1.0, vz=0.0, extra="")
    est, need = estimate(loads_scene(text), speed)
    rel = {f: [a / b - 1.0 for a, b in zip(runs[f], top, strict=True)] for f in BANDS[:-1]}
    return {
        "material": material, "radius_mm": radius * 1e3, "duration_us": top[1] * 1e6,
        "peak_10k": rel[1e4][0], "peak_20k": rel[2e4][0], "duration_10k": rel[1e4][1],
        "v_out_10k": rel[1e4][2], "estimate_10k": est, "band_for_0.5pct_hz": need,
        "peak_10k_tail": tail[0] / top[0] - 1.0, "peak_10k_tail_same_mesh": tail[0] / same[0] - 1.0,
        "peak_10k_same_mesh": runs[1e4][0] / same[0] - 1.0, "peak_40k_mesh": same[0] / top[0] - 1.0,
    }  # fmt: skip


def main(out_dir: Path, speed: float = 3.0, quick: bool = False) -> None:
    out_dir.mkdir(parents=True, exist_ok=True)
    rows, divisions = [], band_divisions()
    materials = ("coal",) if quick else ("coal", "sandstone")
    for material in materials:
        for radius in (0.010, 0.030) if quick else (0.010, 0.015, 0.020, 0.030, 0.040):
            rows.append(row(material, radius, speed, divisions))
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
    lines += ["", *_tail_table(rows, divisions)]
    (out_dir / "table.md").write_text(f"speed {speed:g} m/s\n\n" + "\n".join(lines) + "\n")
    print("\n".join(lines))


def _tail_table(rows, divisions: int) -> list:
    """The peak force of the 10 kHz band with the quasi-static and the dynamic tail."""
    lines = [
        f"peak force at 10 kHz: quasi-static tail and 'ritz' (4 oscillators per contact) "
        f"against 40 kHz on the 10 kHz mesh ({divisions} divisions) and on its own",
        "",
        "| material | radius (mm) | quasi-static vs 40 kHz, same mesh | ritz vs 40 kHz, same "
        "mesh | quasi-static vs 40 kHz | ritz vs 40 kHz | 40 kHz: 10 kHz mesh vs its own |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(
            f"| {r['material']} | {r['radius_mm']:g} | {r['peak_10k_same_mesh']:+.1e} | "
            f"{r['peak_10k_tail_same_mesh']:+.1e} | {r['peak_10k']:+.1e} | "
            f"{r['peak_10k_tail']:+.1e} | {r['peak_40k_mesh']:+.1e} |"
        )
    return lines


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="output folder")
    ap.add_argument("--speed", type=float, default=3.0, help="impact speed, m/s (3.0)")
    ap.add_argument("--quick", action="store_true", help="coal only, radii 10 and 30 mm")
    args = ap.parse_args()
    main(Path(args.out), args.speed, args.quick)
