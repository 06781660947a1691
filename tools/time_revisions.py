"""CPU time of the compiled solvers in this tree against another revision's, interleaved.

    python tools/time_revisions.py --base REV [--rounds 3] [--solver NAME]

``--solver`` picks the scene:

- ``rigid`` (the default): ten coal balls (30 mm, dropped from 0.10-0.19 m gap at
  1.0-1.9 m/s, c = 800 N s/m) on the rigid plate, 1 s, rtol 1e-10, 40 timed runs; prints the
  right-hand-side evaluations (nfev, about 61 000).
- ``coupled``: the two-way coupled modal solver, sandstone at 2 m/s on the closed-form SSSS
  plate (5 kHz band, c = 800 N s/m), 2 ms, 10 runs; prints the force nodes.
- ``stream``: the fast stream solver on the ten-ball scene of the tests (15 deg plate,
  c = 2000 N s/m, d = 2e-5 m, rtol 1e-12, 0.1 s), 10 runs; prints contacts and kernel steps.
- ``active_set``: the compiled active set alone, CPU time per step over 2 ms of simulated
  time of 8 coal balls resting on a 15 deg plate with their neighbour pairs and of 16 with
  all pairs (``resting_set``, as ``benchmarks/bench_active_set.py`` measures), 10 runs each;
  prints the steps.

Each tree runs in its own process with its own numba cache: the scene once (timed on the wall
clock: numba compiles in round 1, the cache is warm in later rounds), then the timed runs in
CPU time (``time.process_time``: less sensitive than the wall clock to other processes on a
shared machine). Prints best and median per tree and round. The trees alternate, so a change
of machine load hits both; the count printed checks that both trees did the same work.
"""

import argparse
import tempfile
from pathlib import Path

from revisions import ROOT, extract_revision, from_either, run_in

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
           lambda r: f"{r.stats['nfev'] if hasattr(r, 'stats') else r.nfev} nfev")  # fmt: skip


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
           lambda r: f"{len(_nodes(r)[0])} nodes")  # fmt: skip


def _nodes(result):
    """The coupled solver's force nodes: on the result's plate part, or on the result itself
    in a revision without one."""
    return result.plate.nodes if getattr(result, "plate", None) is not None else result.nodes


def time_stream(label):
    """Run and time the stream scene (see the module's docstring); print one line."""
    import stream_scenes

    InclinedPlate = from_either("InclinedPlate", "tailbeam.physics.incline")
    Particle = from_either("Particle", "tailbeam.streams.generator")
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


def resting_set(n, all_pairs):
    """An active set of n coal balls (30 mm) at rest on a 15 deg plate (static penetration,
    vz = -0.1 mm/s so that the contacts work), on an 8 x 8 grid 70 mm apart (no two touch);
    pairs: the plate pairs and the neighbours in grid order, or all ball-ball pairs."""
    import math

    from tailbeam import CARBON_STEEL, COAL, Ball, ball_plate_law

    InclinedPlate = from_either("InclinedPlate", "tailbeam.physics.incline")
    ActiveSet = from_either(
        "ActiveSet",
        "tailbeam.solvers.stream.active.integrator.set",
        "tailbeam.solvers.stream.active.set",
        "tailbeam.solvers.stream.active_set",
    )
    radius = 0.03
    incline = InclinedPlate(inclination=15.0)
    law = ball_plate_law(COAL, radius, CARBON_STEEL)
    gn = incline.gravity * math.cos(math.radians(15.0))
    z = radius - law.static_penetration(Ball("p", COAL, radius, (0, 0, 1.0)).mass * gn)
    balls, pairs = [], []
    for b in range(n):
        x, y = -0.245 + 0.07 * (b % 8), -0.245 + 0.07 * (b // 8)
        balls.append(Ball(f"b{b}", COAL, radius, (x, y, z), (0.0, 0.0, -1e-4)))
        pairs.append((b, -1))
    for i in range(n):
        for j in range(i + 1, n if all_pairs else min(i + 2, n)):
            pairs.append((i, j))
    return ActiveSet.from_balls(balls, pairs, incline, rtol=1e-10)


def time_active_set(label):
    """Time the active set's steps alone (see the module's docstring); print one line per set."""
    import time

    import numpy as np

    for n, all_pairs in ((8, False), (16, True)):
        resting_set(n, all_pairs).advance(0.0, 1e-4)  # compile
        cpu = []
        for _ in range(10):
            s = resting_set(n, all_pairs)
            t0 = time.process_time()
            s.advance(0.0, 2e-3)
            cpu.append((time.process_time() - t0) / s.stats["steps"])
        print(f"{label}: n={n} {'all' if all_pairs else 'neighbour'} pairs, "
              f"{s.stats['steps']} steps, CPU per step best {min(cpu) * 1e6:.2f} us, "
              f"median {np.median(cpu) * 1e6:.2f} us", flush=True)  # fmt: skip


def main(base, rounds, solver="rigid"):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        old = extract_revision(base, tmp)
        for r in range(rounds):
            for tree, name, cache in ((old, base, "cache-base"), (ROOT, "this tree", "cache-new")):
                label = f"{solver} round {r + 1}, {name}"
                run_in(tree, tmp / cache, f"time_revisions.time_{solver}({label!r})")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", required=True, help="git revision to compare with")
    parser.add_argument("--rounds", type=int, default=3)
    solvers = ("rigid", "coupled", "stream", "active_set")
    parser.add_argument("--solver", choices=solvers, default="rigid")
    args = parser.parse_args()
    main(args.base, args.rounds, args.solver)
