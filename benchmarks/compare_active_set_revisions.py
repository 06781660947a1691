"""Whether the active set's rigid-plate results are bit-for-bit those of another revision.

    python benchmarks/compare_active_set_revisions.py --base REV

Runs three scenes with every ball in one active set (tests/active_set_driver.py: the ten-ball
scene on a 15 deg plate with c = 0 and with c = 2000, d = 2e-5; the leave scene on 30 deg with
c = 500; 0.1 s, returns every 0.5 ms, rtol 1e-10) in this working tree and in ``git archive
REV`` (its own numba cache), and compares the final states, every force row, kink, contact
record, energy sample and the work counters exactly. Prints one line per scene; exit code 1
if any differs. The first run of each tree compiles the kernels (~15 s each).
"""

import argparse
import importlib
import pickle
import subprocess
import sys
import tarfile
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SCENES = (("ten-ball c=0", "ten_ball_scene", 15.0, {"damping": 0.0}),
          ("ten-ball c=2000", "ten_ball_scene", 15.0, {"damping": 2000.0, "penetration": 2e-5}),
          ("leave c=500", "leave_scene", 30.0, {"damping": 500.0}))  # fmt: skip


def run_scenes(out_path):
    """Run SCENES with the tailbeam and tests found on sys.path; pickle everything."""
    import stream_scenes
    from active_set_driver import SceneRun

    import tailbeam
    from tailbeam.physics.incline import InclinedPlate

    print(f"running {tailbeam.__file__}", flush=True)
    out = {}
    for name, scene, inclination, options in SCENES:
        incline = InclinedPlate(inclination=inclination)
        run = SceneRun(getattr(stream_scenes, scene)(incline), incline, 0.1, sample=5e-4,
                       rtol=1e-10, **options)  # fmt: skip
        s = run.set
        out[name] = {"y": s.y.copy(), "rows": s.force_rows().copy(), "log": [(t, str(kind), p) for t, kind, p in s.kink_log()],
                     "stats": s.stats, "contacts": [repr(vars(c)) for c in run.contacts],
                     "energy": np.array(run.energy), "times": np.array(run.times)}  # fmt: skip
    Path(out_path).write_bytes(pickle.dumps(out))


def _run_in(tree, out_path, cache):
    code = (f"import sys; sys.path[:0] = [{str(tree)!r}, {str(tree / 'tests')!r}, "
            f"{str(ROOT / 'benchmarks')!r}]; import compare_active_set_revisions as c; "
            f"c.run_scenes({str(out_path)!r})")  # fmt: skip
    env = {"NUMBA_CACHE_DIR": str(cache), "OMP_NUM_THREADS": "1", "PATH": "/usr/bin:/bin"}
    subprocess.run([sys.executable, "-c", code], check=True, cwd=tree, env=env)


def _same(a, b):
    """Bit-identical results; the work counters compared on the keys both revisions have
    (a counter added later, such as ``found_again``, is not a difference)."""
    counters = set(a["stats"]) & set(b["stats"])
    return (all(np.array_equal(a[k], b[k]) for k in ("y", "rows", "energy", "times"))
            and all(a[k] == b[k] for k in ("log", "contacts"))
            and all(a["stats"][k] == b["stats"][k] for k in counters))  # fmt: skip


def extract_revision(base, tmp: Path) -> Path:
    """``tailbeam`` and ``tests`` of git revision ``base``, extracted into tmp/base."""
    old = tmp / "base"
    old.mkdir()
    archive = subprocess.run(["git", "archive", base, "tailbeam", "tests"], cwd=ROOT,
                             check=True, capture_output=True).stdout  # fmt: skip
    (tmp / "base.tar").write_bytes(archive)
    with tarfile.open(tmp / "base.tar") as tar:
        tar.extractall(old, filter="data")
    return old


def from_either(name: str, *paths: str):
    """Attribute ``name`` of the first module of ``paths`` that this tree has and that defines
    it: a revision before or after a module moved (the restructure of 0.3.0 moved most of
    them; ``tailbeam.solvers.rigid`` before that was ``tailbeam.rigid``) runs the same code."""
    for path in paths:
        try:
            module = importlib.import_module(path)
        except ModuleNotFoundError as err:
            if not path.startswith(err.name or "-"):
                raise  # a dependency is missing, not the moved module
            continue
        if hasattr(module, name):
            return getattr(module, name)
    raise ImportError(f"none of {paths} defines {name}")


def main(base):
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        old = extract_revision(base, tmp)
        _run_in(old, tmp / "old.pkl", tmp / "cache-base")
        _run_in(ROOT, tmp / "new.pkl", tmp / "cache-new")
        a = pickle.loads((tmp / "old.pkl").read_bytes())
        b = pickle.loads((tmp / "new.pkl").read_bytes())
    ok = True
    for name in a:
        same = _same(a[name], b[name])
        ok &= same
        print(
            f"{name}: {'bit-identical' if same else 'DIFFERENT'} ({a[name]['stats']['steps']} "
            f"steps, {len(a[name]['contacts'])} records, {len(a[name]['rows'])} force rows)"
        )
    return 0 if ok else 1


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--base", required=True, help="git revision to compare with")
    sys.exit(main(parser.parse_args().base))
