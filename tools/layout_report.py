"""The package's layout in numbers, from its sources (ast): modules and lines per folder, the
largest modules, classes (methods, attributes) and functions.

    python tools/layout_report.py [PACKAGE_DIR] [--top N]

PACKAGE_DIR defaults to this tree's ``tailbeam/``; point it at another revision's (``git archive
REV tailbeam | tar -x -C DIR``) to compare two layouts. A class's attributes are the names it
assigns on ``self`` anywhere in its body plus its annotated fields; a function's length counts
its docstring.
"""

import argparse
import ast
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def scan(package: Path):
    """(modules, classes, functions): (path, lines), (path:name, methods, attributes, lines),
    (path:name, lines) of every .py file under ``package``."""
    modules, classes, functions = [], [], []
    for path in sorted(package.rglob("*.py")):
        text = path.read_text()
        rel = str(path.relative_to(package.parent))
        modules.append((rel, len(text.splitlines())))
        tree = ast.parse(text)
        for node in ast.walk(tree):
            if isinstance(node, ast.ClassDef):
                classes.append((f"{rel}:{node.name}", *_class_size(node)))
            elif isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef):
                functions.append((f"{rel}:{node.name}", node.end_lineno - node.lineno + 1))
    return modules, classes, functions


def _class_size(node: ast.ClassDef) -> tuple:
    attrs = {n.attr for n in ast.walk(node) if isinstance(n, ast.Attribute)
             and isinstance(n.ctx, ast.Store) and getattr(n.value, "id", "") == "self"}  # fmt: skip
    attrs |= {n.target.id for n in node.body if isinstance(n, ast.AnnAssign)
              and isinstance(n.target, ast.Name)}  # fmt: skip
    methods = sum(isinstance(n, ast.FunctionDef) for n in node.body)
    return methods, len(attrs), node.end_lineno - node.lineno + 1


def report(package: Path, top: int) -> str:
    modules, classes, functions = scan(package)
    folders = Counter()
    lines_by_folder = Counter()
    for rel, n in modules:
        folder = str(Path(rel).parent)
        folders[folder] += 1
        lines_by_folder[folder] += n
    out = [f"{len(modules)} modules, {sum(n for _, n in modules)} lines, {len(classes)} classes, "
           f"{len(functions)} functions", "", "modules  lines  folder"]  # fmt: skip
    out += [f"{folders[f]:7d} {lines_by_folder[f]:6d}  {f}" for f in sorted(folders)]
    out += ["", "largest modules (lines):"]
    out += [f"  {n:5d}  {rel}" for rel, n in sorted(modules, key=lambda r: -r[1])[:top]]
    out += ["", "largest classes (methods, attributes, lines):"]
    out += [f"  {m:3d} {a:3d} {n:4d}  {name}"
            for name, m, a, n in sorted(classes, key=lambda r: (-r[2], -r[1]))[:top]]  # fmt: skip
    out += ["", "longest functions (lines, docstring included):"]
    out += [f"  {n:4d}  {name}" for name, n in sorted(functions, key=lambda r: -r[1])[:top]]
    return "\n".join(out)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("package", nargs="?", default=str(ROOT / "tailbeam"))
    parser.add_argument("--top", type=int, default=12, help="rows per table")
    args = parser.parse_args()
    print(report(Path(args.package), args.top))
