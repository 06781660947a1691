"""The event restart across the active set's returns (issue 7): markers carried or forgotten.

    python benchmarks/bench_event_restart.py [--seeds A:B] [--duration S] [--no-residual]
                                             [--rtol R] [--out DIR]

Study 2's stream (examples/study_stream_gangue_fraction.py: 30 deg SSSS plate, modes to 5 kHz
coupled both ways, 100 lumps/s, 10-40 mm, contact damping 300 N s/m) for each stream seed,
run twice in child processes of the same code: with the just-applied event markers carried
across the kernel's returns (``active_set.CARRY_FRESH = True``, the fix) and forgotten (False:
the restart as it was before). Without the fix a START or END returned at t can be found
again by the next call at t (a zero-time contact; repeated, the driver's stall that was
retried at rtol / 10). Per run: wall time, the rtol the run ended with (smaller than asked
if the stall retry fired), events found again at their instant (counted by the kernel;
searched again with the fix), contact events of a pair at the time of its previous one
(what finding an event again leaves in the records), contacts, and the physics checks:
energy never created (released - left - at the end - removed at rest - plate >= -1e-9
released, c >= 0), no late start, starts and ends alternating per pair. Per seed: whether
both runs are bit-identical (every event time, ball, kind, partner) and else the first event
where they part: a run with no event found again must be identical (the markers change
nothing else). A stream is chaotic: after the first difference the two runs are different
streams. Writes DIR/restart.csv.
"""

import argparse
import csv
import json
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples"


def run_case(seed, duration, residual, carry, events_path, rtol=1e-10) -> dict:
    """Child process: one stream run; its figures (JSON) and its events (to events_path)."""
    import time

    sys.path.insert(0, str(EXAMPLES))
    from study_stream_gangue_fraction import base_scene

    import tailbeam
    from tailbeam.io.scene_file import parse_scene
    from tailbeam.solvers.stream.active import set as active_set

    active_set.CARRY_FRESH = carry
    data = base_scene(duration, [0.3, 0.8])
    data["streams"][0]["seed"] = seed
    data["plate"]["residual_flexibility"] = residual
    data["sensors"] = []
    t0 = time.perf_counter()
    result = tailbeam.simulate(parse_scene(data), rtol=rtol, progress=False)
    wall = time.perf_counter() - t0
    events = [(float(e.t), e.ball, str(e.kind), str(e.partner)) for e in result.events]
    Path(events_path).write_text(json.dumps(events))
    st = result.stats
    created = -(
        st["energy_released"] - st["energy_left"] - st["energy_final"]
        - st["rest_energy_removed"] - st.get("energy_plate_final", 0.0)
    )  # fmt: skip
    return {
        "wall_s": wall, "rtol": st["rtol"], "found_again": st.get("events_found_again", 0),
        "contacts": len(result.contacts), "late_starts": st["late_starts"],
        "grazing_rests": st.get("grazing_rests", 0),
        "energy_created_rel": created / st["energy_released"],
        "alternate": alternating(events), "same_instant": same_instant(events),
    }  # fmt: skip


def alternating(events) -> bool:
    """Whether every pair's contact events alternate start, end, start, ..."""
    last = {}
    for _, ball, kind, partner in events:
        if kind not in ("contact_start", "contact_end"):
            continue
        key = (ball, partner) if partner == "plate" else tuple(sorted((ball, partner)))
        if last.get(key, "contact_end") == kind:
            return False
        last[key] = kind
    return True


def same_instant(events) -> int:
    """Contact events of a pair at the time of its previous one (a START or END found again
    at the instant it was applied: a zero-time contact or gap)."""
    last, count = {}, 0
    for t, ball, kind, partner in events:
        if kind in ("contact_start", "contact_end"):
            key = (ball, partner) if partner == "plate" else tuple(sorted((ball, partner)))
            count += last.get(key) == t
            last[key] = t
    return count


def _child(out: Path, seed: int, duration: float, residual: bool, carry: bool, rtol) -> dict:
    path = out / f"events_{seed}_{'carry' if carry else 'forget'}.json"
    code = (
        f"import json, sys; sys.path.insert(0, {str(HERE)!r}); import bench_event_restart as b; "
        f"print(json.dumps(b.run_case({seed}, {duration}, {residual}, {carry}, {str(path)!r}, "
        f"{rtol!r})))"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    if done.returncode:
        raise RuntimeError(done.stderr[-2000:])
    res = json.loads(done.stdout.strip().splitlines()[-1])
    res["events"] = json.loads(path.read_text())
    return res


def first_difference(a: list, b: list):
    """Index of the first event where two runs part (None: identical)."""
    for k, (x, y) in enumerate(zip(a, b, strict=False)):
        if x != y:
            return k
    return None if len(a) == len(b) else min(len(a), len(b))


def main(seeds, duration: float, residual: bool, out: Path, rtol: float = 1e-10):
    out.mkdir(parents=True, exist_ok=True)
    jobs = [(s, c) for s in seeds for c in (False, True)]
    with ThreadPoolExecutor(2) as pool:  # two child processes at a time
        done = pool.map(lambda j: _child(out, j[0], duration, residual, j[1], rtol), jobs)
        res = dict(zip(jobs, done, strict=True))
    rows = []
    for seed in seeds:
        forget, carry = res[(seed, False)], res[(seed, True)]
        diff = first_difference(forget.pop("events"), carry.pop("events"))
        for name, r in (("forget", forget), ("carry", carry)):
            rows.append({"seed": seed, "markers": name, **r, "first_difference": diff})
            print(f"seed {seed} {name:6s}: {r['wall_s']:6.1f} s, rtol {r['rtol']:g}, found again "
                  f"{r['found_again']}, same-instant events {r['same_instant']}, contacts "
                  f"{r['contacts']}, late starts {r['late_starts']},"
                  f" energy created / released {r['energy_created_rel']:.1e}, alternating "
                  f"{r['alternate']}; runs part at event {diff}", flush=True)  # fmt: skip
    with open(out / "restart.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    return rows


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", default="1:9", help="stream seeds A:B (B excluded)")
    ap.add_argument("--duration", type=float, default=3.0, help="simulated time, s")
    ap.add_argument("--no-residual", action="store_true", help="plate.residual_flexibility off")
    ap.add_argument("--rtol", type=float, default=1e-10, help="the stream solver's rtol")
    ap.add_argument("--out", default="out/bench_event_restart")
    args = ap.parse_args()
    a, b = (int(v) for v in args.seeds.split(":"))
    main(range(a, b), args.duration, not args.no_residual, Path(args.out), args.rtol)
