"""What the revision tools share: another revision's tree, a process per tree, imports that work
on either side of a module move, and values that unpickle in either tree.

Not a tool itself. Each tool runs its scenes in a child process whose ``sys.path`` starts with
the tree under test, that tree's ``tests/`` (for ``stream_scenes`` and ``active_set_driver``)
and this folder, so the tool's own code is always this tree's and the tailbeam it imports is
the tree's. Every import of a tailbeam internal in code the child runs goes through
``from_either``; what the child pickles holds only builtins and numpy arrays (``plain``), so
the parent can read it whatever module paths the other tree has.
"""

import dataclasses
import enum
import importlib
import pickle
import pickletools
import subprocess
import sys
import tarfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TOOLS = Path(__file__).resolve().parent


def extract_revision(base: str, tmp: Path) -> Path:
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
    """Attribute ``name`` of the first module of ``paths`` that the running tree has and that
    defines it (list the module paths newest first: ``tailbeam.solvers.rigid`` and the older
    ``tailbeam.rigid`` give the same function)."""
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


def plain(obj):
    """``obj`` with every enum replaced by its value and every record (``as_dict()``, a named
    tuple or a dataclass) by a dict, recursively: builtins and numpy arrays only, so a pickle
    of it loads in a tree that lacks the classes (an enum and its string are the same value)."""
    if isinstance(obj, enum.Enum):
        return plain(obj.value)
    if isinstance(obj, type):
        return repr(obj)
    if hasattr(obj, "as_dict"):
        return plain(obj.as_dict())
    if hasattr(obj, "_asdict"):
        return plain(obj._asdict())
    if dataclasses.is_dataclass(obj):
        return plain({f.name: getattr(obj, f.name) for f in dataclasses.fields(obj)})
    if isinstance(obj, dict):
        return {plain(k): plain(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return type(obj)(plain(v) for v in obj)
    if hasattr(obj, "dtype") and getattr(obj, "shape", None) == ():
        return obj.item()  # a numpy scalar
    return obj


def write_plain(obj, path) -> None:
    """Pickle ``plain(obj)`` to ``path``; refuse if the pickle still names a tailbeam class
    (the other tree may not have its module)."""
    data = pickle.dumps(plain(obj))
    names = [arg for op, arg, _ in pickletools.genops(data) if "GLOBAL" in op.name]
    strings = [arg for op, arg, _ in pickletools.genops(data) if isinstance(arg, str)]
    if any("tailbeam" in str(n) for n in names) or any(s.startswith("tailbeam.") for s in strings):
        raise TypeError(f"{path}: the results still refer to a tailbeam class")
    Path(path).write_bytes(data)


def run_in(tree: Path, cache: Path, call: str) -> None:
    """Run ``call`` (Python source, e.g. ``"compare_revisions.run_solvers('out.pkl', True)"``,
    whose module is in this folder) in a fresh single-threaded process on ``tree``'s tailbeam,
    with ``cache`` as its tailbeam and numba cache."""
    module = call.split(".", 1)[0]
    code = (f"import sys; sys.path[:0] = [{str(tree)!r}, {str(tree / 'tests')!r}, "
            f"{str(TOOLS)!r}]; import {module}; {call}")  # fmt: skip
    env = {"TAILBEAM_CACHE_DIR": str(cache), "NUMBA_CACHE_DIR": str(cache / "numba"),
           "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1",
           "PATH": "/usr/bin:/bin"}  # fmt: skip
    subprocess.run([sys.executable, "-c", code], check=True, cwd=tree, env=env)
