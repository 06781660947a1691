"""CPU time of the compiled solvers in this tree against another revision, interleaved.

    python benchmarks/time_revisions.py --base REV [--rounds 3] [--solver NAME]

Scenes. ``rigid`` (the default): ten coal balls (30 mm, dropped from 0.10-0.19 m gap at
1.0-1.9 m/s, c = 800 N s/m), 1 s, rtol 1e-10 (~61 000 right-hand-side evaluations of the law
in the kernel), 40 runs (nfev printed). ``coupled``: the two-way coupled modal solver,
sandstone at 2 m/s on the closed-form SSSS plate (5 kHz band, c = 800 N s/m), 2 ms, 10 runs
(force nodes printed). ``stream``: the fast stream solver on the ten-ball scene of the tests
(15 deg plate, c = 2000 N s/m, d = 2e-5 m, rtol 1e-12, 0.1 s), 10 runs (kernel steps printed).
``active_set``: the compiled active set alone, CPU time per step of 2 ms of simulated time of
8 resting balls with their neighbour pairs and of 16 with all pairs (``bench_active_set``'s
``resting_set``), 10 runs each.

Each tree runs in its own process with its own numba cache (compiled and run once first, not
timed), then the timed runs with ``time.process_time`` (CPU time: less sensitive than the
wall clock to other processes on a shared machine); prints best and median per tree and
round, and the wall time of the first call (numba compiles then: round 1 only, the cache
is warm in later rounds). The trees alternate, so a change of machine load hits both. Same
work in both trees is checked by the count printed.
"""

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

from compare_active_set_revisions import extract_revision, from_either

ROOT = Path(__file__).resolve().parents[1]
REPEATS = 40


def _timed(label, work, repeats, what):
    """Time ``work()`` repeats times (CPU); print best and median and ``what`` of its result."""
    import time

    import numpy as np

    t0 = time.perf_counter()
    res = work()
    first = time.perf_counter() - t0  # (compiles, unless the tree's numba cache is warm)
    cpu = []
    for _ in range(repeats):
        t0 = time.process_time()
        work()
        cpu.append(time.process_time() - t0)
    print(f"{label}: {what(res)}, CPU best {min(cpu) * 1e3:.2f} ms, median "
          f"{np.median(cpu) * 1e3:.2f} ms; first call {first:.1f} s wall", flush=True)  # fmt: skip


def time_rigid(label):
    """Run and time the rigid scene (see the module's docstring); print one line."""
    from tailbeam import CARBON_STEEL, COAL, Ball, Plate, ball_plate_law

    simulate_rigid = from_either("simulate_rigid", "tailbeam.solvers.rigid", "tailbeam.rigid")

    law = ball_plate_law(COAL, 0.03, CARBON_STEEL, damping=800.0, penetration=1e-4)
    balls = [Ball(f"b{i}", COAL, 0.03, (-0.2 + 0.04 * i, 0.0, 0.13 + 0.01 * i),
                  (0.0, 0.0, -1.0 - 0.1 * i)) for i in range(10)]  # fmt: skip
    _timed(label, lambda: simulate_rigid(balls, Plate(), [law] * 10, 1.0, rtol=1e-10), REPEATS,
           lambda r: f"{r.nfev if hasattr(r, 'nfev') else r.stats['nfev']} nfev")  # fmt: skip


def time_coupled(label):
    """Run and time the coupled scene (see the module's docstring); print one line."""
    from tailbeam import CARBON_STEEL, SANDSTONE, Ball, Plate, ball_plate_law

    ssss_kirchhoff_basis = from_either(
        "ssss_kirchhoff_basis", "tailbeam.plate.closed_forms", "tailbeam.modal"
    )

    simulate_coupled = from_either(
        "simulate_coupled", "tailbeam.solvers.coupled", "tailbeam.coupled"
    )
    basis = ssss_kirchhoff_basis(Plate(), 5000.0)
    ball = Ball("s", SANDSTONE, 0.03, (0.07, -0.05, 0.03 + 1e-4), (0.0, 0.0, -2.0))
    law = ball_plate_law(SANDSTONE, 0.03, CARBON_STEEL, damping=800.0)
    _timed(label, lambda: simulate_coupled([ball], basis, [law], 2e-3, gravity=9.80665), 10,
           lambda r: f"{len((r.nodes if hasattr(r, 'nodes') else r.plate.nodes)[0])} nodes")  # fmt: skip


def time_stream(label):
    """Run and time the stream scene (see the module's docstring); print one line."""
    import stream_scenes

    from tailbeam.physics.incline import InclinedPlate
    from tailbeam.streams.generator import Particle

    solve_stream = from_either(
        "solve_stream",
        "tailbeam.solvers.stream.driver.loop",
        "tailbeam.solvers.stream.stream",
        "tailbeam.solvers.stream",
    )
    incline = InclinedPlate(inclination=15.0)
    balls = stream_scenes.ten_ball_scene(incline)
    parts = [Particle(b.name, "", "coal", b.material, b.radius, b.mass, 0.0, tuple(b.position),
                      tuple(b.velocity)) for b in balls]  # fmt: skip

    def work():
        return solve_stream(parts, incline, 0.1, rtol=1e-12, rest_speed=0.0, progress=False,
                            damping=2000.0, penetration=2e-5)  # fmt: skip

    _timed(
        label,
        work,
        10,
        lambda r: f"{len(r.contacts)} contacts, {r.stats['kernel_steps']} kernel steps",
    )


def time_active_set(label):
    """Time the active set's steps alone (see the module's docstring); print one line."""
    import time

    import numpy as np
    from bench_active_set import resting_set

    for n, all_pairs in ((8, False), (16, True)):
        resting_set(n, all_pairs)[0].advance(0.0, 1e-4)  # compile
        cpu = []
        for _ in range(10):
            s = resting_set(n, all_pairs)[0]
            t0 = time.process_time()
            s.advance(0.0, 2e-3)
            cpu.append((time.process_time() - t0) / s.stats["steps"])
        print(f"{label}: n={n} {'all' if all_pairs else 'neighbour'} pairs, "
              f"{s.stats['steps']} steps, CPU per step best {min(cpu) * 1e6:.2f} us, "
              f"median {np.median(cpu) * 1e6:.2f} us", flush=True)  # fmt: skip


def _run_in(tree, cache, label, solver):
    code = (f"import sys; sys.path[:0] = [{str(tree)!r}, {str(tree / 'tests')!r}, "
            f"{str(ROOT / 'benchmarks')!r}]; "
            f"import time_revisions as t; t.time_{solver}({label!r})")  # fmt: skip
    env = {
        "TAILBEAM_CACHE_DIR": str(cache),
        "NUMBA_CACHE_DIR": str(cache / "numba"),
        "OMP_NUM_THREADS": "1",
        "OPENBLAS_NUM_THREADS": "1",
        "PATH": "/usr/bin:/bin",
    }
    subprocess.run([sys.executable, "-c", code], check=True, cwd=tree, env=env)


def main(base, rounds, solver="rigid"):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        old = extract_revision(base, tmp)
        for r in range(rounds):
            _run_in(old, tmp / "cache-base", f"{solver} round {r + 1}, {base}", solver)
            _run_in(ROOT, tmp / "cache-new", f"{solver} round {r + 1}, this tree", solver)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", required=True, help="git revision to compare with")
    parser.add_argument("--rounds", type=int, default=3)
    solvers = ("rigid", "coupled", "stream", "active_set")
    parser.add_argument("--solver", choices=solvers, default="rigid")
    args = parser.parse_args()
    main(args.base, args.rounds, args.solver)
