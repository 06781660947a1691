"""The folders are the layers (issue 7): no module-level import cycle, and no layer imports one
above it (physics < signals, plate < solvers < paper; io and the paper never reach the CLI).

The import graph is read from the sources (ast), not from an interpreter, so a lazy import
inside a function counts for the layer rules (it still couples the layers) but not for the
cycle check (it runs after both modules are loaded).
"""

import ast
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "tailbeam"

# layer -> layers it must never import (a layer is the first folder under tailbeam/, or the
# solver's folder under solvers/; the top-level modules are the core every layer may use)
FORBIDDEN = {
    "physics": {"solvers", "plate", "signals", "paper", "io", "study", "commands", "streams"},
    "signals": {"solvers", "plate", "paper", "io", "study", "commands"},
    "plate": {"solvers", "signals", "paper", "io", "study", "commands"},
    "solvers": {"paper", "io", "study", "commands", "streams"},
    "paper": {"io", "study", "commands"},
    "io": {"solvers", "paper", "study", "commands"},
}


def module_name(path: Path, root: Path) -> str:
    """Dotted name of a source file under ``root`` (a package folder)."""
    parts = list(path.relative_to(root.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def imports(path: Path, names: set, *, top_level: bool) -> set:
    """Modules of ``names`` that ``path`` imports (``from a import b`` names a.b if it is a
    module, else a); only the statements at module level if ``top_level``."""
    tree = ast.parse(path.read_text())
    found = set()
    for node in tree.body if top_level else ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module:
            for alias in node.names:
                sub = f"{node.module}.{alias.name}"
                found.add(sub if sub in names else node.module)
        elif isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
    return found & names


def import_graph(root: Path, *, top_level: bool) -> dict:
    """module -> the modules of the same package it imports."""
    files = {module_name(p, root): p for p in root.rglob("*.py")}
    names = set(files)
    return {m: imports(p, names, top_level=top_level) - {m} for m, p in files.items()}


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


def layer(module: str, graph: dict) -> str:
    """``tailbeam.solvers.stream.engine`` -> ``solvers`` (its folder); top-level modules ->
    ``core``."""
    parts = module.split(".")
    folder = ".".join(parts[:2])
    nested = len(parts) > 1 and any(m.startswith(folder + ".") for m in graph)
    return parts[1] if nested else "core"


def upward_imports(graph: dict) -> list:
    """(module, imported module) pairs that break FORBIDDEN."""
    return sorted(
        (m, t) for m, targets in graph.items() for t in targets
        if layer(t, graph) in FORBIDDEN.get(layer(m, graph), ())
    )  # fmt: skip


def test_no_import_cycle_between_modules():
    graph = import_graph(PACKAGE, top_level=True)
    assert len(graph) > 100 and "tailbeam.solvers.stream.stream" in graph
    assert find_cycle(graph) == []


def test_the_layers_import_only_downwards():
    graph = import_graph(PACKAGE, top_level=False)
    assert graph["tailbeam.solvers.rigid.model"] >= {"tailbeam.physics.impact"}
    assert upward_imports(graph) == []


def test_the_checks_find_a_planted_cycle_and_an_upward_import(tmp_path):
    """The checks against a package whose answer is known: a -> b -> a, and a physics module
    importing the paper."""
    root = tmp_path / "tailbeam"
    (root / "physics").mkdir(parents=True)
    (root / "paper").mkdir()
    for folder in (root, root / "physics", root / "paper"):
        (folder / "__init__.py").write_text("")
    (root / "a.py").write_text("from tailbeam import b\n")
    (root / "b.py").write_text("import tailbeam.a\n")
    (root / "physics" / "law.py").write_text("def f():\n    from tailbeam.paper import claims\n")
    (root / "paper" / "claims.py").write_text("")
    graph = import_graph(root, top_level=True)
    assert find_cycle(graph) == ["tailbeam.a", "tailbeam.b", "tailbeam.a"]
    assert upward_imports(graph) == []  # the function-level import is not at module level
    everything = import_graph(root, top_level=False)
    assert upward_imports(everything) == [("tailbeam.physics.law", "tailbeam.paper.claims")]
