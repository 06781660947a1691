"""No error or warning message advises a setting that does not exist.

The messages are read from tailbeam's sources (ast): the arguments of every ``raise X(...)``,
``warnings.warn(...)`` and ``note(...)`` call, f-string pieces joined. An advice is a verb
(raise, set, lower, increase, decrease, reduce, shorten, enlarge, use, pass, give) followed
by one or more names (``raise max_contacts, or rest_speed``); a name is a setting when it
starts with ``--``, holds ``_`` or ``.``, is written ``name=`` somewhere in the message, or
is a documented name. Each setting must be documented where a user can set it:

- a scene key: a row `` `plate.tail` `` of docs/scene-files.md, or a sweep-file key of
  docs/datasets.md (``balls[2].radius`` is the
  row ``balls.radius``; a bare ``residual_flexibility`` is the last part of one row);
- a command-line option: a row `` `tailbeam simulate --out` `` of docs/cli.md;
- a keyword of the library call ``tailbeam.simulate(scene, *, ...)`` as README.md gives it;
- a parameter of the function that raises the message (or of a function enclosing it): a
  library setting of the call that failed (``raise max_steps`` where ``max_steps`` was
  passed in).

The known offenders are listed in ``KNOWN`` with why, each an xfail(strict=True): when its
message is fixed the test passes unexpectedly and the entry must be removed.
"""

import ast
import functools
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "tailbeam"
VERBS = "raise|set|lower|increase|decrease|reduce|shorten|enlarge|use|pass|give"
NAME = r"--[a-z][\w-]*|[A-Za-z_][\w]*(?:\[\d+\])?(?:\.[A-Za-z_]\w*(?:\[\d+\])?)*="
ADVICE = re.compile(rf"\b({VERBS})\s+((?:{NAME}?)(?:\s*,?\s*(?:or|and)?\s*(?:{NAME}?))*)")
ROW = re.compile(r"^\|\s*`([^`|]+)`\s*\|", re.MULTILINE)
SIGNATURE = re.compile(r"tailbeam\.simulate\(scene, \*, ([^)]*)\)")

# (module, setting) -> why it is an offender today. Remove an entry when its message is fixed.
KNOWN: dict = {}


def _text(node) -> str:
    """The string an expression builds, with '{}' for each computed part."""
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.JoinedStr):
        return "".join(_text(v) if isinstance(v, ast.Constant) else "{}" for v in node.values)
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        return _text(node.left) + _text(node.right)
    return " {} "


def _call_name(call: ast.Call) -> str:
    func = call.func
    return getattr(func, "attr", None) or getattr(func, "id", "")


def _walk(node, params=frozenset()):
    """(node, parameter names of the functions enclosing it) for every node under ``node``."""
    if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)):
        a = node.args
        params = params | {x.arg for x in a.posonlyargs + a.args + a.kwonlyargs}
    yield node, params
    for child in ast.iter_child_nodes(node):
        yield from _walk(child, params)


def messages(path: Path):
    """(line, text, parameters) of every message raised, warned or noted in ``path``; the
    parameters are those of the functions enclosing it."""
    for node, params in _walk(ast.parse(path.read_text())):
        call = None
        if isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call):
            call = node.exc
        elif isinstance(node, ast.Call) and _call_name(node) in ("warn", "note"):
            call = node
        if call is not None:
            parts = [_text(a) for a in call.args] + [_text(k.value) for k in call.keywords]
            yield call.lineno, " ".join(parts), params


@functools.cache
def documented() -> frozenset:
    """Every name a user can set (module docstring), normalised (no indices, no '=')."""
    scene = ROW.findall((ROOT / "docs" / "scene-files.md").read_text())
    scene += ROW.findall((ROOT / "docs" / "datasets.md").read_text())  # sweep-file keys
    names = set(scene) | {key.rsplit(".", 1)[-1] for key in scene}
    for row in ROW.findall((ROOT / "docs" / "cli.md").read_text()):
        names.update(w for w in row.split() if w.startswith("--"))
    signature = SIGNATURE.search((ROOT / "README.md").read_text())
    names.update(p.split("=")[0].strip() for p in signature.group(1).split(","))
    return frozenset(names)


def _normal(name: str) -> str:
    return re.sub(r"\[\d+\]", "", name).split("=")[0]


def advice(text: str, known_names: set) -> list:
    """The settings ``text`` advises to change (module docstring)."""
    found = []
    for match in ADVICE.finditer(text):
        for token in re.split(r"\s*,\s*|\s+or\s+|\s+and\s+|\s+", match.group(2)):
            name = _normal(token.strip(" ,"))
            if not name or name in ("or", "and"):
                continue
            if (
                name.startswith("--")
                or "_" in name
                or "." in name
                or re.search(rf"\b{re.escape(name)}\s?=", text)
                or name in known_names
            ):
                found.append(name)
    return found


@functools.cache
def all_advice() -> tuple:
    """(module, line, setting, message, parameters) of every advice in the package."""
    names = documented()
    out = []
    for path in sorted(PACKAGE.rglob("*.py")):
        module = str(path.relative_to(ROOT))
        for line, text, params in messages(path):
            for name in advice(text, names):
                out.append((module, line, name, " ".join(text.split()), params))
    return tuple(out)


def _params():
    for module, line, name, text, params in all_advice():
        marks = ()
        if (module, name) in KNOWN:
            marks = pytest.mark.xfail(strict=True, reason=KNOWN[(module, name)])
        yield pytest.param(name, text, params, id=f"{module}:{line}:{name}", marks=marks)


@pytest.mark.parametrize(("setting", "message", "params"), list(_params()))
def test_advice_names_a_setting_that_exists(setting, message, params):
    assert setting in documented() or setting in params, (
        f"the message advises {setting!r}, which is neither a documented scene key "
        f"(docs/scene-files.md), a command option (docs/cli.md), a keyword of "
        f"tailbeam.simulate (README.md) nor a parameter of the function raising it: {message}"
    )


def test_only_the_known_offenders_are_listed():
    """Every entry of KNOWN still matches an advice (a stale entry would hide nothing)."""
    found = {(module, name) for module, _, name, _, _ in all_advice()}
    assert set(KNOWN) <= found


def test_the_scan_finds_advice_in_messages_and_not_elsewhere(tmp_path):
    """The scan itself: advice in raised, warned and noted messages is found, with its
    settings split at 'or' and commas; a comment or docstring is not a message."""
    src = tmp_path / "m.py"
    src.write_text(
        '"""Docstring: raise not_a_message."""\n'
        "# comment: raise also_not\n"
        "def f(n):\n"
        "    if n:\n"
        "        raise ValueError(f'too many steps ({n}); raise max_contacts, or rest_speed')\n"
        "    warnings.warn('lower plate.fmax')\n"
        "    note('use --out')\n"
        "    raise RuntimeError('did not converge to tol=' + str(n) + '; raise tol')\n"
    )
    found = [advice(text, set()) for _, text, _ in messages(src)]
    assert sorted(sum(found, [])) == sorted(
        ["max_contacts", "rest_speed", "plate.fmax", "--out", "tol"]
    )


def test_the_documented_names_come_from_the_manual():
    names = documented()
    assert {"plate.tail_modes", "sample_rate", "balls.radius", "--out", "--fmax"} <= names
    assert {"max_steps", "rtol"} <= names  # tailbeam.simulate's keywords in README.md
    assert "steps_per_contact" not in names
