"""The manual defines every scene key, stream key, sweep-file key and command option exactly
once, and every relative link in it resolves.

A definition is a Markdown table row whose first cell is the name in backticks and nothing
else, e.g. ``| `plate.tail` | meaning | default |``. Names: scene keys as dotted paths
(``duration``, ``plate.tail``, ``balls.radius``, ``materials.NAME.density``,
``sensors.noise.rms``, ``streams.rate``); sweep-file keys (``scene``, ``labels.coal``,
``axes.KEY.low``); command options as typed (``tailbeam simulate --solver``, positionals in
capitals: ``tailbeam simulate SCENE``; an option every command shares: ``tailbeam COMMAND
--quiet``). The sources of truth are the key tuples of the scene-file, stream and sweep-file
parsers and the command-line parser itself.
"""

import argparse
import re
from pathlib import Path

from tailbeam.cli import build_parser
from tailbeam.io.scene_dump import MATERIAL_KEYS
from tailbeam.io.scene_file import (
    BALL_KEYS,
    CONTACT_KEYS,
    FRICTION_KEYS,
    FRICTION_PAIR_KEYS,
    MODAL_KEYS,
    NOISE_KEYS,
    PLATE_KEYS,
    SENSOR_KEYS,
    SUPPORT_KEYS,
    TOP_KEYS,
)
from tailbeam.streams.generator import KEYS as STREAM_KEYS
from tailbeam.study.sweep_file import DISTRIBUTIONS, SWEEP_KEYS

ROOT = Path(__file__).resolve().parents[1]
DEFINITION = re.compile(r"^\|\s*`([^`|]+)`\s*\|")
# defined names that look like a key or an option but that the code does not know
CHECKED_PREFIXES = ("contact.", "plate.", "materials.", "balls.", "sensors.", "streams.",
                    "labels.", "axes.")  # fmt: skip
CLI_NAME = re.compile(r"^tailbeam( \S+)? (--[\w-]+|[A-Z]+)$")
FENCE = re.compile(r"^(```|~~~)")
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
SCHEME = re.compile(r"^[a-z][a-z0-9+.-]*:", re.IGNORECASE)


def manual_pages() -> list:
    return [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


# -- what the code defines ------------------------------------------------------------------------


def scene_keys() -> list:
    """Every key of a scene file, as the manual names it."""
    names = list(TOP_KEYS)
    names += [f"contact.{k}" for k in CONTACT_KEYS]
    names += [f"contact.friction.{k}" for k in FRICTION_KEYS]
    names += [f"contact.friction.pairs.{k}" for k in FRICTION_PAIR_KEYS]
    names += [f"plate.{k}" for k in PLATE_KEYS + MODAL_KEYS]
    names += [f"plate.supports.{k}" for k in SUPPORT_KEYS]
    names += [f"materials.NAME.{k}" for k in MATERIAL_KEYS]
    names += [f"balls.{k}" for k in BALL_KEYS]
    names += [f"sensors.{k}" for k in SENSOR_KEYS]
    names += [f"sensors.noise.{k}" for k in NOISE_KEYS]
    names += [f"streams.{k}" for k in STREAM_KEYS]
    return names


def sweep_keys() -> list:
    """Every key of a sweep file. The nested ones are spelled out in the parser's checks
    (tailbeam.study.sweep_file): ``[labels] coal``, a distribution's ``distribution`` and
    ``samples`` with its parameters, ``follow`` with ``scale`` and ``offset``."""
    axis = {"distribution", "samples", "follow", "scale", "offset"}
    axis |= {p for params in DISTRIBUTIONS.values() for p in params}
    return [*SWEEP_KEYS, "labels.coal", *(f"axes.KEY.{k}" for k in sorted(axis))]


def _name(action) -> str:
    if action.option_strings:
        return max(action.option_strings, key=len)  # --quiet rather than -q
    return (action.metavar if isinstance(action.metavar, str) else action.dest).upper()


def cli_options(parser=None) -> list:
    """Every option and positional argument of every command (help left out). An option every
    command has, with the same help, is one name: ``tailbeam COMMAND --quiet``."""
    parser = parser or build_parser()
    top, commands = [], {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            commands = dict(action.choices)
        elif not isinstance(action, argparse._HelpAction):
            top.append(f"tailbeam {_name(action)}")
    per_command = {
        name: {_name(a): a.help for a in sub._actions if not isinstance(a, argparse._HelpAction)}
        for name, sub in commands.items()
    }
    shared = set.intersection(*(set(opts.items()) for opts in per_command.values()))
    names = top + [f"tailbeam COMMAND {option}" for option, _help in sorted(shared)]
    for command, options in per_command.items():
        names += [f"tailbeam {command} {o}" for o, h in options.items() if (o, h) not in shared]
    return names


# -- what the manual defines ----------------------------------------------------------------------


def _prose_lines(text: str):
    """(line number, line) outside fenced code blocks."""
    fenced = False
    for number, line in enumerate(text.splitlines(), start=1):
        if FENCE.match(line.strip()):
            fenced = not fenced
            continue
        if not fenced:
            yield number, line


def definitions(texts: dict) -> dict:
    """{name: ["page:line", ...]} of every definition row in ``texts`` ({page: text})."""
    found = {}
    for page, text in texts.items():
        for number, line in _prose_lines(text):
            match = DEFINITION.match(line)
            if match:
                found.setdefault(match.group(1).strip(), []).append(f"{page}:{number}")
    return found


def check_definitions(expected, texts: dict) -> tuple:
    """(missing, duplicated, unknown): expected names without a definition row; names defined
    more than once ({name: places}); defined names that look like keys or options but are not
    expected ({name: places})."""
    found = definitions(texts)
    expected = set(expected)
    missing = sorted(expected - set(found))
    duplicated = {n: p for n, p in sorted(found.items()) if n in expected and len(p) > 1}
    unknown = {
        n: p
        for n, p in sorted(found.items())
        if n not in expected and (n.startswith(CHECKED_PREFIXES) or CLI_NAME.match(n))
    }
    return missing, duplicated, unknown


def report(missing, duplicated, unknown) -> str:
    lines = []
    if missing:
        lines.append("not defined in the manual (add one row '| `NAME` | meaning | default |'):")
        lines += [f"    {n}" for n in missing]
    if duplicated:
        lines.append("defined more than once (keep one definition, link to it elsewhere):")
        lines += [f"    {n}: {', '.join(p)}" for n, p in duplicated.items()]
    if unknown:
        lines.append("defined in the manual but unknown to the code (renamed or removed?):")
        lines += [f"    {n}: {', '.join(p)}" for n, p in unknown.items()]
    return "\n".join(lines)


def manual_texts() -> dict:
    return {str(p.relative_to(ROOT)): p.read_text(encoding="utf-8") for p in manual_pages()}


# -- links ----------------------------------------------------------------------------------------


def slug(heading: str) -> str:
    """The anchor GitHub gives a heading: lower case, punctuation dropped, spaces -> '-'."""
    return re.sub(r"[^\w\- ]", "", heading.strip().lower()).replace(" ", "-")


def anchors(text: str) -> set:
    seen, out = {}, set()
    for _number, line in _prose_lines(text):
        match = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if match:
            base = slug(match.group(1))
            count = seen.get(base, 0)
            seen[base] = count + 1
            out.add(base if count == 0 else f"{base}-{count}")
    return out


def broken_links(pages) -> list:
    """["page:line: target (why)"] for every relative link (and image) in ``pages`` whose file
    does not exist, or whose #anchor is not a heading of the Markdown file it points to."""
    out = []
    for page in pages:
        text = page.read_text(encoding="utf-8")
        for number, line in _prose_lines(text):
            for target in LINK.findall(re.sub(r"`[^`]*`", "", line)):
                if SCHEME.match(target):
                    continue
                path, _, anchor = target.partition("#")
                file = (page.parent / path).resolve() if path else page
                where = f"{page.relative_to(ROOT) if ROOT in page.parents else page}:{number}"
                if not file.exists():
                    out.append(f"{where}: {target} (no such file)")
                elif anchor and file.suffix == ".md":
                    if anchor not in anchors(file.read_text(encoding="utf-8")):
                        out.append(f"{where}: {target} (no heading with that anchor)")
    return out


# -- tests ----------------------------------------------------------------------------------------


def test_every_key_and_option_is_defined_once_in_the_manual():
    expected = scene_keys() + sweep_keys() + cli_options()
    missing, duplicated, unknown = check_definitions(expected, manual_texts())
    assert not (missing or duplicated or unknown), "\n" + report(missing, duplicated, unknown)


def test_the_checker_reports_missing_duplicated_and_unknown_names():
    planted = {
        "docs/a.md": "| key | meaning |\n|---|---|\n| `plate.model` | rigid or modal |\n"
        "| `plate.nonsense` | a key the code does not have |\n",
        "docs/b.md": "```\n| `plate.size` | inside a code block: not a definition |\n```\n"
        "| `plate.model` | defined again |\n| `plate.size`, `plate.material` | two names |\n"
        "the text may mention `plate.size` freely\n",
    }
    missing, duplicated, unknown = check_definitions(["plate.model", "plate.size"], planted)
    assert missing == ["plate.size"]
    assert duplicated == {"plate.model": ["docs/a.md:3", "docs/b.md:4"]}
    assert unknown == {"plate.nonsense": ["docs/a.md:4"]}
    message = report(missing, duplicated, unknown)
    assert "plate.size" in message and "docs/a.md:3, docs/b.md:4" in message
    assert "plate.nonsense" in message


def test_the_options_are_read_from_the_parser():
    names = cli_options()
    for name in (
        "tailbeam --version",
        "tailbeam COMMAND --quiet",
        "tailbeam simulate SCENE",
        "tailbeam simulate --solver",
        "tailbeam modes --no-cache",
        "tailbeam sweep --scheduler",
        "tailbeam learn --out",
    ):
        assert name in names, name
    assert not [n for n in names if n.endswith(("--help", "-h"))]
    assert "tailbeam simulate --quiet" not in names  # shared: named once
    commands = {n.split()[1] for n in names if not n.split()[1].startswith("-")}
    assert {"reproduce", "simulate", "modes", "sweep", "features", "learn"} <= commands


def test_every_relative_link_resolves():
    broken = broken_links(manual_pages())
    assert not broken, "broken links:\n" + "\n".join(broken)


def test_the_link_checker_reports_broken_links(tmp_path):
    (tmp_path / "there.md").write_text("# A page\n\n## Its part\n")
    page = tmp_path / "page.md"
    page.write_text(
        "[ok](there.md) [ok](there.md#its-part) [ok](#here) [web](https://example.org/x)\n"
        "`[in code](nowhere.md)`\n"
        "[gone](missing.md) [bad anchor](there.md#no-part) ![img](img/none.png)\n\n## Here\n"
    )
    broken = broken_links([page])
    assert len(broken) == 3, broken
    assert "missing.md (no such file)" in broken[0]
    assert "there.md#no-part (no heading" in broken[1]
    assert "img/none.png (no such file)" in broken[2]
