"""The overlap checks of the preflight (tailbeam.preflight.overlaps): time against the number
of bodies, against a brute-force search over every pair as the baseline (same answer
required).

- ball-ball: n balls of radius 0.5 mm on a touching square grid (every neighbour touches, no
  pair overlaps: the worst case for the k-d tree's candidate pairs), k-d tree against numpy
  brute force (n^2 distances, only up to ``BRUTE_MAX``);
- stream particles against balls: the 1038 particles of examples/caving_stream.toml against
  n falling balls of radius 5 mm, k-d tree over (x, y, z, c t) against brute force (every
  particle against every ball's free fall at its release time).

    python benchmarks/bench_overlaps.py --out DIR [--quick]

Writes DIR/table.md and DIR/overlaps.csv.
"""

import argparse
import csv
import sys
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tailbeam.errors import InputError  # noqa: E402
from tailbeam.io.scene_file import load_scene  # noqa: E402
from tailbeam.physics.bodies import Ball  # noqa: E402
from tailbeam.physics.materials import COAL  # noqa: E402
from tailbeam.preflight.overlaps import (  # noqa: E402
    TOUCH_TOLERANCE,
    check_ball_pairs,
    check_particles_against_balls,
    undisturbed_path,
)

BRUTE_MAX = 5000  # balls: n^2 / 2 distances beyond are not worth the baseline's memory


def grid_balls(n, r=5e-4):
    k = int(np.ceil(np.sqrt(n)))
    xs = -0.28 + 2 * r * np.arange(k)
    return [Ball(f"b{i}", COAL, r, (xs[i % k], xs[i // k], r)) for i in range(n)]


def brute_pairs(balls) -> bool:
    """Whether any pair overlaps, from every distance."""
    c = np.array([b.position for b in balls])
    r = np.array([b.radius for b in balls])
    for j in range(1, len(balls)):
        d = np.linalg.norm(c[:j] - c[j], axis=1)
        if np.any(d < (r[:j] + r[j]) * (1 - TOUCH_TOLERANCE)):
            return True
    return False


def timed(fn, *args):
    start = time.perf_counter()
    try:
        fn(*args)
        found = False
    except InputError:
        found = True
    return time.perf_counter() - start, found


def brute_particles(scene) -> bool:
    """Whether any particle overlaps any ball at its release: every pair, numpy over the
    particles for each ball."""
    first = len(scene.balls)
    g, half = scene.incline.gravity_vector, scene.incline.half_sizes
    t = np.array([p.t_release for p in scene.particles[first:]])
    x = np.array([p.position for p in scene.particles[first:]])
    r = np.array([p.radius for p in scene.particles[first:]])
    for b in scene.balls:
        t_end, acc = undisturbed_path(b, g, scene.duration, half)
        tk = t[:, None]
        where = np.asarray(b.position) + np.asarray(b.velocity) * tk + 0.5 * acc * tk * tk
        d = np.linalg.norm(x - where, axis=1)
        if np.any((t <= t_end) & (d < (b.radius + r) * (1 - TOUCH_TOLERANCE))):
            return True
    return False


def falling_balls(n, z0):
    return tuple(
        Ball(
            f"b{i}",
            COAL,
            0.005,
            (-0.25 + 0.05 * (i % 10), -0.25 + 0.05 * (i // 10 % 10), z0 + 0.02 * (i // 100)),
        )  # fmt: skip
        for i in range(n)
    )


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, metavar="DIR")
    parser.add_argument("--quick", action="store_true", help="smaller sizes")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    sizes = (1000, 5000) if args.quick else (1000, 5000, 20_000, 100_000)
    for n in sizes:
        balls = grid_balls(n)
        t_tree, found = timed(check_ball_pairs, balls)
        t_brute = found_brute = None
        if n <= BRUTE_MAX:
            start = time.perf_counter()
            found_brute = brute_pairs(balls)
            t_brute = time.perf_counter() - start
            assert found_brute == found
        rows.append(("ball-ball, touching grid", n, t_tree, t_brute, found))
    stream = load_scene(ROOT / "examples" / "caving_stream.toml")
    _ = stream.particles  # generated once, outside the timings
    counts = (10, 100) if args.quick else (10, 100, 1000)
    for n in counts:
        for z0 in (0.6, 2.0):
            scene = replace(stream, balls=falling_balls(n, z0), labels=())
            _ = scene.particles
            t_tree, found = timed(check_particles_against_balls, scene)
            start = time.perf_counter()
            assert brute_particles(scene) == found
            t_brute = time.perf_counter() - start
            label = f"1038 particles vs balls from z = {z0} m"
            rows.append((label, n, t_tree, t_brute, found))
    with open(out / "overlaps.csv", "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["case", "bodies", "tree_s", "brute_force_s", "overlap_found"])
        w.writerows(rows)
    lines = [
        "| case | balls | k-d tree, s | brute force, s | overlap found |",
        "|---|---|---|---|---|",
    ]
    for case, n, t_tree, t_brute, found in rows:
        brute = "-" if t_brute is None else f"{t_brute:.3g}"
        lines.append(f"| {case} | {n} | {t_tree:.3g} | {brute} | {found} |")
    (out / "table.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
