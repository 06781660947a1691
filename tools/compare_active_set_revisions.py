"""Whether the stream solver's compiled active set gives, bit for bit, another revision's results.

    python tools/compare_active_set_revisions.py --base REV

Runs three scenes with every ball in one active set (``tests/active_set_driver.py`` of each
tree: the ten-ball scene on a 15 deg plate with c = 0 and with c = 2000 N s/m, d = 2e-5 m; the
leave scene on a 30 deg plate with c = 500 N s/m; 0.1 s, a return every 0.5 ms, rtol 1e-10) in
this working tree and in ``git archive REV``, each in its own process with its own numba cache,
and compares exactly: the final state, every force row, every kink handled inside the kernel
(time, kind, pair), every contact record (fields and derived values), the energy at every
return and the work counters both revisions count. An enum and its value are the same value.
Prints one line per scene ("bit-identical" or what differs); exit code 1 if any differs. The
first run of each tree compiles the kernels (about 15 s each).
"""

import argparse
import pickle
import sys
import tempfile
from pathlib import Path

import numpy as np
from revisions import ROOT, extract_revision, from_either, run_in, write_plain

SCENES = (("ten-ball c=0", "ten_ball_scene", 15.0, {"damping": 0.0}),
          ("ten-ball c=2000", "ten_ball_scene", 15.0, {"damping": 2000.0, "penetration": 2e-5}),
          ("leave c=500", "leave_scene", 30.0, {"damping": 500.0}))  # fmt: skip


def run_scenes(out_path):
    """Run SCENES with the tailbeam and tests on sys.path; pickle the results as plain values."""
    import stream_scenes
    from active_set_driver import SceneRun

    import tailbeam

    InclinedPlate = from_either("InclinedPlate", "tailbeam.physics.incline")

    print(f"running {tailbeam.__file__}", flush=True)
    out = {}
    for name, scene, inclination, options in SCENES:
        incline = InclinedPlate(inclination=inclination)
        run = SceneRun(getattr(stream_scenes, scene)(incline), incline, 0.1, sample=5e-4,
                       rtol=1e-10, **options)  # fmt: skip
        s = run.set
        result = {"y": s.y.copy(), "rows": s.force_rows().copy(), "log": s.kink_log(),
                  "stats": s.stats, "contacts": list(run.contacts),
                  "energy": np.array(run.energy), "times": np.array(run.times)}  # fmt: skip
        out[name] = result
    write_plain(out, out_path)


def _records(records, keys) -> list:
    """Records (dicts) as reprs of the ``keys`` they share: a float compares by its bits (nan
    equals nan), a field one revision added is not compared."""
    return [repr({k: rec[k] for k in sorted(keys)}) for rec in records]


def differences(a, b) -> list:
    """What differs between two revisions' results of one scene (empty: bit-identical). The
    work counters and the record fields are compared on the keys both revisions have."""
    arrays = ("y", "rows", "energy", "times")
    out = [k for k in arrays if not np.array_equal(a[k], b[k], equal_nan=True)]
    out += ["kink log"] * (repr(a["log"]) != repr(b["log"]))
    records = a["contacts"] + b["contacts"]
    shared = set.intersection(*(set(r) for r in records)) if records else set()
    same = _records(a["contacts"], shared) == _records(b["contacts"], shared)
    out += ["contact records"] * (not same or len(a["contacts"]) != len(b["contacts"]))
    counters = sorted(set(a["stats"]) & set(b["stats"]))
    out += [f"stats.{k}" for k in counters if a["stats"][k] != b["stats"][k]]
    return out


def main(base):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        old = extract_revision(base, tmp)
        for tree, name in ((old, "old"), (ROOT, "new")):
            call = f"compare_active_set_revisions.run_scenes({str(tmp / f'{name}.pkl')!r})"
            run_in(tree, tmp / f"cache-{name}", call)
        a = pickle.loads((tmp / "old.pkl").read_bytes())
        b = pickle.loads((tmp / "new.pkl").read_bytes())
    ok = True
    for name in a:
        diff = differences(a[name], b[name])
        ok &= not diff
        what = "bit-identical" if not diff else "DIFFERENT: " + ", ".join(diff)
        print(f"{name}: {what} ({a[name]['stats']['steps']} steps, {len(a[name]['contacts'])} "
              f"records, {len(a[name]['rows'])} force rows)")  # fmt: skip
    return 0 if ok else 1


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", required=True, help="git revision to compare with")
    sys.exit(main(parser.parse_args().base))
