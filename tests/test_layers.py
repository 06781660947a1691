"""The package's layers: every module belongs to one, imports go down only, and there are no
import cycles, counting imports at any depth (module level and inside functions).

The import graph is read from the sources (ast), not from an interpreter, so a lazy import
inside a function counts as much as one at the top: both couple the modules. The checks are
shown to fail on a package with planted violations (the last tests).
"""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "tailbeam"

# The levels, bottom to top. A module imports modules of its own room or of a room on a lower
# level; rooms on the same level never import each other. A module's room is the one with the
# longest prefix of its dotted name (the package itself, ``tailbeam``, names only its
# ``__init__``).
LEVELS = (
    {
        "ground": (
            "tailbeam._version",
            "tailbeam.errors",
            "tailbeam.progress",
            "tailbeam.cachedir",
            "tailbeam.jit",
        )
    },
    {"physics": ("tailbeam.physics",)},
    {"plate": ("tailbeam.plate",), "signals": ("tailbeam.signals",)},
    {"streams": ("tailbeam.streams",)},
    {"scene": ("tailbeam.scene",)},
    {"results": ("tailbeam.results",), "preflight": ("tailbeam.preflight",)},
    {"io": ("tailbeam.io",)},
    {"numerics": ("tailbeam.solvers", "tailbeam.solvers.numerics")},
    {"plate loads": ("tailbeam.solvers.plate_loads",)},
    {"protocol": ("tailbeam.solvers.base",), "modal setup": ("tailbeam.solvers.modal_setup",)},
    {"rigid": ("tailbeam.solvers.rigid",)},
    {"coupled": ("tailbeam.solvers.coupled",), "stream": ("tailbeam.solvers.stream",)},
    {"single ball": ("tailbeam.solvers.single_ball",), "run cost": ("tailbeam.solvers.run_cost",)},
    {"simulation": ("tailbeam.simulation",)},
    {"paper": ("tailbeam.paper",), "study": ("tailbeam.study",)},
    {"cli": ("tailbeam.cli",)},
    {"facade": ("tailbeam", "tailbeam.__main__")},
)


def module_name(path: Path, root: Path) -> str:
    """Dotted name of a source file under ``root`` (a package folder)."""
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path: Path, names: set) -> set:
    """Modules of ``names`` that ``path`` imports anywhere in its source (``from a import b``
    names a.b if that is a module, else a; ``importlib.import_module("a.b")`` with a constant
    string names a.b, and a computed string the package itself, so it cannot hide an edge)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module:
            for alias in node.names:
                sub = f"{node.module}.{alias.name}"
                found.add(sub if sub in names else node.module)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif _is_import_module(node):
            arg = node.args[0] if node.args else None
            literal = isinstance(arg, ast.Constant) and isinstance(arg.value, str)
            found.add(arg.value if literal else "tailbeam")
    return found & names


def _is_import_module(node) -> bool:
    func = getattr(node, "func", None)
    return isinstance(node, ast.Call) and (
        getattr(func, "attr", None) == "import_module" or getattr(func, "id", None) == "__import__"
    )


def import_graph(root: Path) -> dict:
    """module -> the modules of the same package it imports (at any depth)."""
    files = {module_name(p, root): p for p in root.rglob("*.py")}
    names = set(files)
    return {m: imports(p, names) - {m} for m, p in files.items()}


def room(module: str, levels=LEVELS) -> tuple[int, str] | None:
    """(level, room) of a module: the room with the longest prefix of its name; None if no
    room claims it."""
    best = None
    for level, rooms in enumerate(levels):
        for name, prefixes in rooms.items():
            for prefix in prefixes:
                inside = "." in prefix and module.startswith(prefix + ".")
                if module == prefix or inside:
                    if best is None or len(prefix) > best[0]:
                        best = (len(prefix), level, name)
    return None if best is None else best[1:]


def unassigned(graph: dict, levels=LEVELS) -> list:
    return sorted(m for m in graph if room(m, levels) is None)


def upward_imports(graph: dict, levels=LEVELS) -> list:
    """(module, imported module, why) for every import that does not go down: to a higher
    level, or to another room of the same level."""
    out = []
    for m, targets in graph.items():
        here = room(m, levels)
        for t in targets:
            there = room(t, levels)
            if here is None or there is None or there == here:
                continue
            if there[0] > here[0]:
                out.append((m, t, f"{here[1]} imports {there[1]}, a level above"))
            elif there[0] == here[0]:
                out.append((m, t, f"{here[1]} imports {there[1]}, a room beside it"))
    return sorted(out)


def find_cycle(graph: dict) -> list:
    """One import cycle of ``graph`` as a list of modules (first == last), or []."""
    state = {}  # 1: on the current path, 2: done

    def visit(node, path):
        state[node] = 1
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                return path[path.index(nxt) :] + [nxt]
            if nxt not in state and (cycle := visit(nxt, path + [nxt])):
                return cycle
        state[node] = 2
        return []

    for start in sorted(graph):
        if start not in state and (cycle := visit(start, [start])):
            return cycle
    return []


def test_every_module_belongs_to_a_layer():
    graph = import_graph(PACKAGE)
    assert len(graph) > 100 and "tailbeam.solvers.stream.solver" in graph
    assert unassigned(graph) == []


def test_the_layers_import_only_downwards():
    graph = import_graph(PACKAGE)
    assert graph["tailbeam.solvers.rigid.regions"] >= {"tailbeam.physics.impact"}
    assert upward_imports(graph) == []


# The active set's own layers: the compiled kernel at the bottom, its Python wrapper and the
# plate side of its pairs beside each other above it, the driver's view (``members``,
# ``islands``, ...) on top.
ACTIVE = "tailbeam.solvers.stream.active"
ACTIVE_LEVELS = (
    {"compiled": (f"{ACTIVE}.compiled",)},
    {"integrator": (f"{ACTIVE}.integrator",), "plate": (f"{ACTIVE}.plate",)},
    {"members": (ACTIVE,)},
)


def test_the_active_set_imports_only_downwards():
    graph = import_graph(PACKAGE)
    assert graph[f"{ACTIVE}.members"] >= {f"{ACTIVE}.integrator.set", f"{ACTIVE}.plate.pairs"}
    assert upward_imports(graph, ACTIVE_LEVELS) == []


def test_no_import_cycle_at_any_depth():
    assert find_cycle(import_graph(PACKAGE)) == []


def test_the_version_has_one_home():
    """``__version__`` is defined in ``tailbeam/_version.py`` only and imported from there."""
    defined, imported_from_package = [], []
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Assign) and any(
                getattr(t, "id", None) == "__version__" for t in node.targets
            ):
                defined.append(path.name)
            if isinstance(node, ast.ImportFrom) and node.module == "tailbeam":
                if any(a.name == "__version__" for a in node.names):
                    imported_from_package.append(str(path.relative_to(PACKAGE)))
    assert defined == ["_version.py"]
    assert imported_from_package == []


def _plant(tmp_path) -> Path:
    """A package whose answers are known: a cycle a -> b -> a (b's import inside a function),
    a physics module importing the paper inside a function, plate importing signals (a room
    beside it), a module no room claims, and a computed import_module."""
    root = tmp_path / "tailbeam"
    for folder in ("physics", "paper", "plate", "signals"):
        (root / folder).mkdir(parents=True)
        (root / folder / "__init__.py").write_text("")
    (root / "misc").mkdir()
    (root / "__init__.py").write_text("")
    (root / "errors.py").write_text("import tailbeam.progress\n")
    (root / "progress.py").write_text("def f():\n    from tailbeam import errors\n")
    (root / "physics" / "law.py").write_text("def f():\n    from tailbeam.paper import claims\n")
    (root / "paper" / "claims.py").write_text("import importlib\nimportlib.import_module(x)\n")
    (root / "plate" / "modes.py").write_text("from tailbeam.signals.sensor import Spec\n")
    (root / "signals" / "sensor.py").write_text("")
    (root / "misc" / "odd.py").write_text("")
    return root


def test_the_checks_find_planted_violations(tmp_path):
    root = _plant(tmp_path)
    levels = (
        {"ground": ("tailbeam.errors", "tailbeam.progress")},
        {"physics": ("tailbeam.physics",)},
        {"plate": ("tailbeam.plate",), "signals": ("tailbeam.signals",)},
        {"paper": ("tailbeam.paper",)},
        {"facade": ("tailbeam",)},
    )
    graph = import_graph(root)
    assert find_cycle(graph) == ["tailbeam.errors", "tailbeam.progress", "tailbeam.errors"]
    assert unassigned(graph, levels) == ["tailbeam.misc.odd"]
    assert graph["tailbeam.paper.claims"] == {"tailbeam"}  # the computed import
    assert upward_imports(graph, levels) == [
        ("tailbeam.paper.claims", "tailbeam", "paper imports facade, a level above"),
        ("tailbeam.physics.law", "tailbeam.paper.claims", "physics imports paper, a level above"),
        (
            "tailbeam.plate.modes",
            "tailbeam.signals.sensor",
            "plate imports signals, a room beside it",
        ),
    ]
