"""Coulomb's law with stick and slip as events against the regularised law, on a stream.

    python benchmarks/bench_friction_coulomb.py --out DIR [--particles N] [--extra S] [--slow]

The first N lumps (default 10; the stream reference takes at most 20 bodies) of
``examples/caving_stream.toml``'s stream on the rigid 30-degree plate (released at 200 per
second, the run lasting N / 200 + S s; S = 0.5 by default), integrated by the
``stream-reference`` solver (scipy DOP853, rtol 1e-10) frictionless, with the regularised
law (mu_s 0.5, mu_d 0.4, mu_r 0.1, v_d = 2 v_s) at v_s = 1e-2 and 1e-3 m/s (and 1e-4 with
``--slow``), and with Coulomb's law (v_s = v_d = 0). Rows: DOP853 steps, process CPU
time, contacts, events of Coulomb's law, and against Coulomb's run the largest difference
of a lump's final centre
(m; lumps still on the plate in both) and of a plate contact's tangential impulse
(relative to the largest, contacts matched by lump and order). Writes DIR/table.md and
DIR/results.json; prints the machine's load.
"""

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from bench_friction_stream import scene_text  # noqa: E402

from tailbeam.io.scene_file import loads_scene  # noqa: E402
from tailbeam.physics.contacts import contact_table  # noqa: E402
from tailbeam.solvers.stream.reference.solver import simulate_stream_reference  # noqa: E402

CASES = (("frictionless", None), ("v_s 1e-2", 1e-2), ("v_s 1e-3", 1e-3), ("v_s 1e-4", 1e-4),
         ("Coulomb", 0.0))  # fmt: skip
SLOW = "v_s 1e-4"  # ~10x the steps of v_s 1e-3: only with --slow


def run(n: int, extra: float, stiction):
    """(``StreamReferenceResult``, CPU s) of the stream reference on n lumps with the given
    stiction velocity (None: frictionless; 0: Coulomb's law)."""
    text = scene_text(n, "rigid", stiction)
    text = text.replace(f"duration = {n / 200.0 + 1.0!r}", f"duration = {n / 200.0 + extra!r}")
    scene = loads_scene(text)
    particles = scene.particles
    cpu = time.process_time()
    result = simulate_stream_reference(
        [p.ball() for p in particles], scene.incline, scene.duration, rtol=1e-10,
        contacts=contact_table(particles, scene.contacts(), scene.incline.plate.material),
        release_times=[p.t_release for p in particles], friction=scene.friction,
        max_steps=10**6,
    )  # fmt: skip
    return result, time.process_time() - cpu


def final_centres(result) -> dict:
    """Lump name -> final centre (3,) m, for the lumps still on the plate at the end."""
    names, x, _v = result.states[-1]
    return {name: x[k] for k, name in enumerate(names)}


def tangential_impulses(result) -> dict:
    """(lump, n-th plate contact) -> tangential impulse (N s)."""
    seen, out = {}, {}
    for c in result.contacts:
        if c.partner != "plate":
            continue
        k = seen[c.ball] = seen.get(c.ball, 0) + 1
        out[(c.ball, k)] = c.tangential_impulse
    return out


def compare(result, truth) -> tuple:
    """(largest final-centre distance m, largest tangential-impulse difference relative to
    the largest impulse) against ``truth``."""
    a, b = final_centres(result), final_centres(truth)
    common = set(a) & set(b)
    dist = max((float(np.linalg.norm(a[k] - b[k])) for k in common), default=float("nan"))
    ia, ib = tangential_impulses(result), tangential_impulses(truth)
    scale = max(ib.values(), default=0.0)
    keys = set(ia) & set(ib)
    dj = max((abs(ia[k] - ib[k]) for k in keys), default=float("nan"))
    return dist, dj / scale if scale > 0 else float("nan")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True)
    parser.add_argument("--particles", type=int, default=10)
    parser.add_argument("--extra", type=float, default=0.5)
    parser.add_argument("--slow", action="store_true", help="also v_s = 1e-4 m/s")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    print(f"load before: {os.getloadavg()}", file=sys.stderr)
    runs = {}
    for name, stiction in CASES:
        if name == SLOW and not args.slow:
            continue
        result, cpu = run(args.particles, args.extra, stiction)
        runs[name] = (result, cpu)
        print(f"{name}: {result.steps} steps, {cpu:.1f} CPU s", file=sys.stderr)
    truth = runs["Coulomb"][0]
    rows = []
    for name, (result, cpu) in runs.items():
        coulomb_events = sum(
            str(e.kind) in ("stick", "slip", "roll_hold", "roll_free") for e in result.events
        )
        dist, dj = compare(result, truth) if name not in ("Coulomb", "frictionless") else (
            float("nan"), float("nan"))  # fmt: skip
        rows.append({"case": name, "steps": result.steps, "cpu_s": cpu,
                     "contacts": len(result.contacts), "coulomb_events": coulomb_events,
                     "centre_m": dist, "tangential_impulse_rel": dj})  # fmt: skip
    load = os.getloadavg()
    print(f"load after: {load}", file=sys.stderr)
    lines = [
        f"{args.particles} lumps, {args.particles / 200.0 + args.extra:g} s simulated, "
        f"stream-reference rtol 1e-10, load average after {load[0]:.1f}",
        "",
        "| case | DOP853 steps | CPU s | contacts | stick/slip events | final centre vs "
        "Coulomb (m) | tangential impulse vs Coulomb |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(f"| {r['case']} | {r['steps']} | {r['cpu_s']:.1f} | {r['contacts']} | "
                     f"{r['coulomb_events']} | {r['centre_m']:.2g} | "
                     f"{r['tangential_impulse_rel']:.2g} |")  # fmt: skip
    (out / "table.md").write_text("\n".join(lines) + "\n")
    (out / "results.json").write_text(json.dumps(rows, indent=1))
    print("\n".join(lines))
    return 0


if __name__ == "__main__":
    sys.exit(main())
