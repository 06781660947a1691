"""One ball on the reference stream scene's own modal bases, with and without residual
flexibility at the contact: how far the 10 and 20 kHz bands are from the top band.

    python benchmarks/bench_stream_residual.py [--bands 10000 20000 40000] [--damping 300]

The bases are those ``tailbeam simulate examples/caving_stream.toml`` builds for each band
(FE, theory and mesh chosen from the band, cached); a 30 mm sandstone ball at 2 m/s lands at
(0.07, -0.05) m on the horizontal plate and runs through the stream solver (rtol 1e-10).
Prints duration, v_out and peak force per band and their relative difference from the top
band. The meshes change with the band, so this is truncation plus mesh, not truncation only.
"""

import argparse
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
import bench_stream  # noqa: E402

from tailbeam import SANDSTONE, Ball  # noqa: E402
from tailbeam.io.scene_file import load_scene  # noqa: E402
from tailbeam.physics.incline import InclinedPlate  # noqa: E402
from tailbeam.simulation import _stream_plate, stream_band  # noqa: E402
from tailbeam.solvers.stream.driver.loop import solve_stream  # noqa: E402
from tailbeam.solvers.stream.plate import StreamPlate  # noqa: E402
from tailbeam.streams.generator import Particle  # noqa: E402

R = 0.03
BALL = Ball("s", SANDSTONE, R, (0.07, -0.05, R + 1e-4), (0.0, 0.0, -2.0))


def contact(plate, damping):
    """(duration s, v_out m/s, peak force N) of the ball's first contact on ``plate``."""
    p = [Particle("s", "", "coal", SANDSTONE, R, BALL.mass, 0.0, tuple(BALL.position),
                  tuple(BALL.velocity))]  # fmt: skip
    run = solve_stream(p, InclinedPlate(), 1e-3, damping=damping, rtol=1e-10, progress=False,
                       plate=plate)  # fmt: skip
    c = run.contacts[0]
    return np.array([c.t_end - c.t_start, c.v_out, c.peak_force])


def main(bands, damping, out="out/bench_stream_residual"):
    Path(out).mkdir(parents=True, exist_ok=True)
    res = {}
    for fmax in bands:
        path = Path(out) / f"scene_{fmax:g}.toml"
        path.write_text(bench_stream.scene_text(10, "modal", fmax, True))
        scene = load_scene(str(path))
        base = _stream_plate(scene, stream_band(scene))
        for residual in (True, False):
            plate = StreamPlate(base.basis, base.zeta, residual_flexibility=residual)
            res[fmax, residual] = contact(plate, damping)
            info = base.basis.info.get("mesh", "")
            print(f"{fmax:g} Hz, {base.basis.n_modes} modes, {base.basis.theory}, {info}, "
                  f"residual {residual}: {res[fmax, residual]}")  # fmt: skip
    top = max(bands)
    for (fmax, residual), v in res.items():
        if fmax != top:
            diff = (v - res[top, residual]) / res[top, residual]
            print(f"{fmax:g} vs {top:g} Hz, residual {residual}: duration, v_out, peak "
                  f"{diff[0]:.2e} {diff[1]:.2e} {diff[2]:.2e}")  # fmt: skip


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bands", type=float, nargs="+", default=[10000.0, 20000.0, 40000.0])
    parser.add_argument("--damping", type=float, default=300.0)
    args = parser.parse_args()
    main(args.bands, args.damping)
