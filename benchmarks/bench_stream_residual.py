"""One ball on the reference stream scene's own modal bases, with and without residual
flexibility at the contact: how far the lower bands are from the top band.

    python benchmarks/bench_stream_residual.py --out DIR [--bands 10000 20000 40000]
        [--damping 300]

Reproduces the one-ball figure at the end of docs/streams.md ("Band and particle size"). The
bases are those ``tailbeam simulate examples/caving_stream.toml`` builds for each band (FE
Mindlin, mesh chosen from the band, cached); a 30 mm sandstone ball at 2 m/s lands at
(0.07, -0.05) m on the horizontal plate and runs through the stream solver (rtol 1e-10,
c = ``--damping`` N s/m), with the static residual spring and without residual flexibility.
Baseline, in the same run: the top band with the same setting. Reports the contact duration,
v_out and peak force per band and their relative difference from the top band; the meshes
change with the band, so this is truncation and mesh together.

Writes DIR/bench_stream_residual.csv and DIR/table.md (and the scene files it built).
"""

import argparse
import csv
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
import bench_stream  # noqa: E402

from tailbeam import SANDSTONE, Ball  # noqa: E402
from tailbeam.io.scene_file import load_scene  # noqa: E402
from tailbeam.physics.incline import InclinedPlate  # noqa: E402
from tailbeam.plate.basis import modal_damping  # noqa: E402
from tailbeam.solvers.modal_setup.band import stream_band  # noqa: E402
from tailbeam.solvers.modal_setup.setup import build_basis  # noqa: E402
from tailbeam.solvers.stream.driver.loop import solve_stream  # noqa: E402
from tailbeam.solvers.stream.plate import StreamPlate  # noqa: E402
from tailbeam.streams.generator import Particle  # noqa: E402

R = 0.03
BALL = Ball("s", SANDSTONE, R, (0.07, -0.05, R + 1e-4), (0.0, 0.0, -2.0))
QUANTITIES = ("duration", "v_out", "peak_force")


def contact(plate, damping):
    """(duration s, v_out m/s, peak force N) of the ball's first contact on ``plate``."""
    p = [Particle("s", "", "gangue", SANDSTONE, R, BALL.mass, 0.0, tuple(BALL.position),
                  tuple(BALL.velocity))]  # fmt: skip
    run = solve_stream(p, InclinedPlate(), 1e-3, damping=damping, rtol=1e-10, progress=False,
                       plate=plate)  # fmt: skip
    c = run.contacts[0]
    return np.array([c.t_end - c.t_start, c.v_out, c.peak_force])


def scene_basis(path: Path):
    """The modal basis and damping ratios a stream scene file runs on (its band's basis)."""
    scene = load_scene(str(path))
    basis = build_basis(scene, stream_band(scene))
    return basis, modal_damping(basis.omega, scene.modal.damping_ratio, scene.modal.rayleigh)


def main(out_dir, bands=(10000.0, 20000.0, 40000.0), damping=300.0):
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    res, meshes = {}, {}
    for fmax in bands:
        path = out / f"scene_{fmax:g}.toml"
        path.write_text(bench_stream.scene_text(10, "modal", fmax, True))
        basis, zeta = scene_basis(path)
        meshes[fmax] = (basis.n_modes, basis.theory, basis.info.get("divisions", ""))
        for residual in (True, False):
            plate = StreamPlate(basis, zeta, residual_flexibility=residual)
            res[fmax, residual] = contact(plate, damping)
            print(f"{fmax:g} Hz, {meshes[fmax]}, residual {residual}: {res[fmax, residual]}",
                  flush=True)  # fmt: skip
    top = max(bands)
    rows = []
    for (fmax, residual), v in res.items():
        diff = (v - res[top, residual]) / res[top, residual]
        n_modes, theory, divisions = meshes[fmax]
        rel = {f"{q}_vs_top": d for q, d in zip(QUANTITIES, diff, strict=True)}
        rows.append({"band_hz": fmax, "residual": residual, "modes": n_modes, "theory": theory,
                     "divisions": divisions, **dict(zip(QUANTITIES, v, strict=True)),
                     **rel})  # fmt: skip
    with open(out / "bench_stream_residual.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    lines = [f"One sandstone ball (30 mm, 2 m/s), c = {damping:g} N s/m; relative difference "
             f"from the {top / 1e3:g} kHz basis with the same residual setting.", "",
             "| band (kHz) | modes | mesh divisions | residual flexibility | duration | v_out | "
             "peak force |", "|---|---|---|---|---|---|---|"]  # fmt: skip
    for r in sorted(rows, key=lambda r: (not r["residual"], r["band_hz"])):
        lines.append(f"| {r['band_hz'] / 1e3:g} | {r['modes']} | {r['divisions']} | "
                     f"{'on' if r['residual'] else 'off'} | {r['duration_vs_top']:+.1e} | "
                     f"{r['v_out_vs_top']:+.1e} | {r['peak_force_vs_top']:+.1e} |")  # fmt: skip
    (out / "table.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--bands", type=float, nargs="+", default=[10000.0, 20000.0, 40000.0],
                        help="bands, Hz; the last is the top band compared with")  # fmt: skip
    parser.add_argument("--damping", type=float, default=300.0, help="contact damping, N s/m")
    args = parser.parse_args()
    main(args.out, args.bands, args.damping)
