"""CPU time of the compiled rigid solver in this tree against another revision, interleaved.

    python benchmarks/time_revisions.py --base REV [--rounds 3]

Scene: ten coal balls (30 mm, dropped from 0.10-0.19 m gap at 1.0-1.9 m/s, c = 800 N s/m),
1 s, rtol 1e-10 (~61 000 right-hand-side evaluations of the law in the kernel). Each tree runs
in its own process with its own numba cache (compiled first, not timed), then 40 runs timed
with ``time.process_time`` (CPU time: less sensitive than the wall clock to other processes
on a shared machine); prints best and median per tree and round. The trees alternate, so a
change of machine load hits both. Same work in both trees is checked (nfev printed).
"""

import argparse
import subprocess
import sys
import tempfile
from pathlib import Path

from compare_active_set_revisions import extract_revision, import_either

ROOT = Path(__file__).resolve().parents[1]
REPEATS = 40


def time_rigid(label):
    """Run and time the scene with the tailbeam on sys.path; print one line."""
    import time

    import numpy as np

    from tailbeam import CARBON_STEEL, COAL, Ball, Plate, ball_plate_law

    simulate_rigid = import_either("tailbeam.solvers.rigid", "tailbeam.rigid").simulate_rigid

    law = ball_plate_law(COAL, 0.03, CARBON_STEEL, damping=800.0, penetration=1e-4)
    balls = [Ball(f"b{i}", COAL, 0.03, (-0.2 + 0.04 * i, 0.0, 0.13 + 0.01 * i),
                  (0.0, 0.0, -1.0 - 0.1 * i)) for i in range(10)]  # fmt: skip
    res = simulate_rigid(balls, Plate(), [law] * 10, 1.0, rtol=1e-10)
    cpu = []
    for _ in range(REPEATS):
        t0 = time.process_time()
        simulate_rigid(balls, Plate(), [law] * 10, 1.0, rtol=1e-10)
        cpu.append(time.process_time() - t0)
    print(f"{label}: {res.nfev} nfev, CPU best {min(cpu) * 1e3:.2f} ms, median "
          f"{np.median(cpu) * 1e3:.2f} ms", flush=True)  # fmt: skip


def _run_in(tree, cache, label):
    code = (f"import sys; sys.path[:0] = [{str(tree)!r}, {str(ROOT / 'benchmarks')!r}]; "
            f"import time_revisions as t; t.time_rigid({label!r})")  # fmt: skip
    env = {
        "TAILBEAM_CACHE_DIR": str(cache),
        "NUMBA_CACHE_DIR": str(cache / "numba"),
        "OMP_NUM_THREADS": "1",
        "OPENBLAS_NUM_THREADS": "1",
        "PATH": "/usr/bin:/bin",
    }
    subprocess.run([sys.executable, "-c", code], check=True, cwd=tree, env=env)


def main(base, rounds):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        old = extract_revision(base, tmp)
        for r in range(rounds):
            _run_in(old, tmp / "cache-base", f"round {r + 1}, {base}")
            _run_in(ROOT, tmp / "cache-new", f"round {r + 1}, this tree")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", required=True, help="git revision to compare with")
    parser.add_argument("--rounds", type=int, default=3)
    args = parser.parse_args()
    main(args.base, args.rounds)
