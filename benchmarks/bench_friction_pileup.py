"""Lumps piling up on the beam with friction: the fast stream solver's rest rule (sleep).

    python benchmarks/bench_friction_pileup.py --out DIR [--quick] [--counts 125 250 500]

The scene: coal and sandstone lumps (30 % gangue, radii 10-40 mm) released at 100 per second
from 0.02-0.15 m above a 0.4 x 0.5 m area of the upper half of a rigid 20-degree beam
(1.2 x 0.6 m, x downhill), friction
mu_s = mu_d = 0.7, rolling resistance mu_r = 0.5 (tan 20 deg = 0.36: a lump that stops stays),
v_s = 1e-3 m/s, v_d = 2e-3 m/s, damping 300 N s/m; the stream lasts n / 100 s and the
simulation 1 s longer (500 lumps: 5 s of stream, 6 s simulated). The plate loads are not
kept (``solve_stream(loads=False)``, as ``tailbeam simulate`` runs a rigid plate's scene);
each row gives the process's peak resident memory.

Rows, each case in its own process (timed inside it, after a warm-up that fills the numba
cache): wall and CPU time (the process's: the machine may be shared), kernel steps,
contacts, groups frozen and lumps woken, the fraction of the
lumps still on the plate that are asleep at the end, the energy ledger (released = final +
left + removed at rest + friction; its residual, which must not be a gain), and the fitted
exponent of wall and CPU time against the number of lumps; ``--one-set`` integrates the
active set as one set (a private switch, ``loop._ISLANDS``) in place of its islands.
``--compare`` adds the same short pile with sleeping disabled (full integration of the
resting lumps) and the differences of the final positions and energy. Writes
DIR/table.md and DIR/results.json (DIR/rows.json after each case); prints the machine's
load (``os.getloadavg``) before and after: the machine may be shared.
"""

import argparse
import json
import os
import resource
import sys
import time
from pathlib import Path

import numpy as np
from child import run_case_in_child

RATE = 100.0  # lumps per second

SCENE = """
duration = {duration!r}
[contact]
damping = 300.0
penetration = 1e-5
[contact.friction]
static = 0.7
dynamic = 0.7
stiction_velocity = 1e-3
transition_velocity = 2e-3
rolling = 0.5
[plate]
model = "rigid"
inclination = 20.0
size = [1.2, 0.6, 0.02]
[[streams]]
name = "pile"
rate = {rate!r}
start = 0.0
stop = {stop!r}
gangue_fraction = 0.3
radius = [0.01, 0.04]
area = [[-0.5, -0.1], [-0.25, 0.25]]
height = [0.02, 0.15]
seed = 1
"""


def scene_text(n: int, extra: float = 1.0) -> str:
    """The pile-up scene with n lumps (stream n / RATE s, simulation ``extra`` s longer)."""
    stop = n / RATE
    return SCENE.format(duration=stop + extra, rate=RATE, stop=stop)


def run_case(n: int, sleep: bool, extra: float = 1.0, islands: bool = True) -> dict:
    """Child process: simulate the scene of n lumps, report wall time and the ledger."""
    from tailbeam.io.scene_file import loads_scene
    from tailbeam.solvers.stream.driver import loop
    from tailbeam.solvers.stream.driver.loop import solve_stream

    loop._ISLANDS = islands
    scene = loads_scene(scene_text(n, extra))
    t0, c0 = time.perf_counter(), time.process_time()
    run = solve_stream(scene.particles, scene.incline, scene.duration,
                       contacts=scene.contacts(), friction=scene.friction, sleep=sleep,
                       progress=False, max_work=10**9, loads=False)  # fmt: skip
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    s = run.stats
    books = s["energy_final"] + s["energy_left"] + s["rest_energy_removed"] + s["energy_friction"]
    on_plate = len(run.final)
    return {
        "lumps": n, "sleep": sleep, "wall_s": wall, "cpu_s": cpu,
        "kernel_steps": int(s["kernel_steps"]), "islands": islands,
        "islands_max": int(s.get("islands_max", 1)),
        "steps_undone": int(s.get("island_steps_undone", 0)),
        "contacts": int(s["contacts"]), "sleeps": int(s.get("sleeps", 0)),
        "wakes": int(s.get("wakes", 0)), "sleep_refused": int(s.get("sleep_refused", 0)),
        "on_plate": on_plate, "asleep": int(s.get("asleep_final", 0)),
        "at_rest_fraction": s.get("asleep_final", 0) / on_plate if on_plate else 0.0,
        "slow_fraction": _slow(run) / on_plate if on_plate else 0.0,
        "energy_released": s["energy_released"], "energy_booked": books,
        "energy_residual": books - s["energy_released"], "late_starts": int(s["late_starts"]),
        "peak_rss_MB": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1e3,
        "final": {k: [list(map(float, x)), list(map(float, v))] for k, (x, v) in run.final.items()},
    }  # fmt: skip


def _slow(run, speed: float = 1e-3) -> int:
    """Lumps on the plate moving slower than ``speed`` (m/s) at the end."""
    return sum(float(np.linalg.norm(v)) < speed for _x, v in run.final.values())


def _in_child(n: int, sleep: bool, extra: float = 1.0, islands: bool = True) -> dict:
    return run_case_in_child("bench_friction_pileup", n, sleep, extra, islands)


def compare(a: dict, b: dict) -> dict:
    """Largest final-position difference (m) and the energy difference (J) of two runs of
    one scene (sleeping and not)."""
    common = sorted(set(a["final"]) & set(b["final"]))
    dx = [np.linalg.norm(np.subtract(a["final"][k][0], b["final"][k][0])) for k in common]
    return {
        "lumps_compared": len(common), "lumps_only_in_one": len(set(a["final"]) ^ set(b["final"])),
        "largest_position_difference_m": float(max(dx)) if dx else 0.0,
        "median_position_difference_m": float(np.median(dx)) if dx else 0.0,
        "energy_final_difference_J": a["energy_booked"] - b["energy_booked"],
    }  # fmt: skip


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--counts", type=int, nargs="+", default=[125, 250, 500])
    ap.add_argument("--quick", action="store_true", help="counts 25 50 100")
    ap.add_argument("--compare", type=int, default=0, metavar="N",
                    help="also run N lumps with sleeping off and compare")  # fmt: skip
    ap.add_argument("--compare-extra", type=float, default=0.5, metavar="S",
                    help="the compared runs last S s past the stream (default 0.5)")  # fmt: skip
    ap.add_argument("--one-set", action="store_true",
                    help="integrate the active set as one set, not as islands")  # fmt: skip
    args = ap.parse_args(argv)
    counts = [25, 50, 100] if args.quick else args.counts
    args.out.mkdir(parents=True, exist_ok=True)
    print(f"load before: {os.getloadavg()}", file=sys.stderr)
    _in_child(10, True)  # warm-up: numba cache
    rows = []
    for n in counts:
        row = _in_child(n, True, 1.0, not args.one_set)
        rows.append(row)
        print(f"{n} lumps: {row['wall_s']:.1f} s, {row['cpu_s']:.1f} s CPU, "
              f"{row['peak_rss_MB']:.0f} MB peak, asleep "
              f"{row['at_rest_fraction']:.2f}, energy residual {row['energy_residual']:.3g} J",
              file=sys.stderr)  # fmt: skip
        partial = [{k: v for k, v in r.items() if k != "final"} for r in rows]
        (args.out / "rows.json").write_text(json.dumps(partial, indent=1))  # (as they come)
    result = {"rows": [{k: v for k, v in r.items() if k != "final"} for r in rows]}
    if len(rows) >= 2:
        lumps = np.log([r["lumps"] for r in rows])
        for key, col in (("cost_exponent", "wall_s"), ("cpu_exponent", "cpu_s")):
            result[key] = float(np.polyfit(lumps, np.log([r[col] for r in rows]), 1)[0])
    if args.compare:
        extra = args.compare_extra
        on, off = _in_child(args.compare, True, extra), _in_child(args.compare, False, extra)
        result["compare"] = {"sleep": {k: v for k, v in on.items() if k != "final"},
                             "no_sleep": {k: v for k, v in off.items() if k != "final"},
                             **compare(on, off)}  # fmt: skip
    result["load_after"] = os.getloadavg()
    print(f"load after: {result['load_after']}", file=sys.stderr)
    (args.out / "results.json").write_text(json.dumps(result, indent=1))
    (args.out / "table.md").write_text(table(result))
    print(table(result))
    return 0


def table(result: dict) -> str:
    """The rows as a markdown table."""
    head = ("| lumps | wall s (CPU s) | kernel steps (undone) | most islands | contacts "
            "| frozen / woken | asleep at end | energy residual J (of released) |")  # fmt: skip
    lines = [head, "|---|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        lines.append(
            f"| {r['lumps']} | {r['wall_s']:.1f} ({r['cpu_s']:.1f}) | {r['kernel_steps']} "
            f"({r['steps_undone']}) | {r['islands_max'] if r['islands'] else 'one set'} | "
            f"{r['contacts']} | "
            f"{r['sleeps']} / {r['wakes']} | {r['asleep']} of {r['on_plate']} "
            f"({r['at_rest_fraction']:.0%}) | {r['energy_residual']:.2e} "
            f"({r['energy_released']:.3g}) |"
        )  # fmt: skip
    if "cost_exponent" in result:
        lines.append(f"\ncost exponent against lumps: wall time {result['cost_exponent']:.2f}, "
                     f"CPU time {result['cpu_exponent']:.2f}")  # fmt: skip
    if "compare" in result:
        c = result["compare"]
        lines.append(
            f"\nsleep vs full integration, {c['sleep']['lumps']} lumps: largest final position "
            f"difference {c['largest_position_difference_m']:.3g} m (median "
            f"{c['median_position_difference_m']:.3g} m), energy difference "
            f"{c['energy_final_difference_J']:.3g} J; wall {c['sleep']['wall_s']:.1f} s vs "
            f"{c['no_sleep']['wall_s']:.1f} s, kernel steps {c['sleep']['kernel_steps']} vs "
            f"{c['no_sleep']['kernel_steps']}"
        )  # fmt: skip
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    sys.exit(main())
