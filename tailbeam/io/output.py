"""Output folders that hold exactly one run: checked before the work, replaced atomically.

A command first calls ``check_output_dir(path, field="--out")`` (before any work: a path that
is a file, or a folder that is not a tailbeam output folder, is refused with one line). Its
results then go to a temporary folder beside the target; only when every file is written does
that folder replace the old one (renames on one file system), with ``manifest.json`` listing
what was written. A failed run leaves the old folder untouched; a successful one leaves no
file of an earlier run behind.
"""

import contextlib
import json
import os
import shutil
import tempfile
from datetime import datetime, timezone
from pathlib import Path

from tailbeam.errors import InputError

MANIFEST = "manifest.json"


def check_output_dir(out_dir, *, field: str = "--out") -> Path:
    """Refuse, before any work, an output path tailbeam may not replace.

    Allowed: a path that does not exist, an empty folder, or a folder holding a tailbeam
    ``manifest.json`` (an earlier run's outputs, which the new run replaces whole).
    """
    out_dir = Path(out_dir)
    if out_dir.exists() and not out_dir.is_dir():
        raise InputError(field, f"{str(out_dir)!r} exists and is not a folder")
    if out_dir.is_dir() and any(out_dir.iterdir()) and not (out_dir / MANIFEST).is_file():
        raise InputError(
            field,
            f"the folder {str(out_dir)!r} is not empty and holds no tailbeam {MANIFEST}, so it "
            "is not an earlier tailbeam output to replace; choose a new or empty folder",
        )
    parent = out_dir.resolve().parent
    if parent.exists() and not os.access(parent, os.W_OK):
        raise InputError(field, f"cannot write in {str(parent)!r}")
    return out_dir


def _write_manifest(folder: Path, command: str, files: dict) -> None:
    listed = sorted(str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file())
    from tailbeam._version import __version__

    manifest = {
        "tailbeam_version": __version__,
        "command": command,
        "written_utc": datetime.now(timezone.utc).isoformat(timespec="seconds"),
        "files": {name: files.get(name, {}) for name in listed},
    }
    (folder / MANIFEST).write_text(json.dumps(manifest, indent=2, allow_nan=False) + "\n")


_METADATA: dict = {}  # temporary folder -> {relative file name: metadata}


def describe(path, **metadata) -> Path:
    """Record ``metadata`` (units, sample rate, ...) of ``path``, a file being written inside
    an ``atomic_output_dir``; it goes into that folder's manifest.json. Returns ``path``."""
    path = Path(path)
    for folder, files in _METADATA.items():
        if folder in path.parents:
            files.setdefault(str(path.relative_to(folder)), {}).update(metadata)
    return path


@contextlib.contextmanager
def atomic_output_dir(out_dir, *, command: str = "", field: str = "--out"):
    """Yield a temporary folder for the outputs; on success it replaces ``out_dir`` whole.

    Every file written there is listed in ``manifest.json`` with the metadata given to
    ``describe``. On any exception ``out_dir`` is left as it was.
    """
    out_dir = check_output_dir(out_dir, field=field)
    out_dir.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.new.", dir=out_dir.parent))
    _METADATA[tmp] = {}
    try:
        yield tmp
        _write_manifest(tmp, command, _METADATA[tmp])
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
    finally:
        _METADATA.pop(tmp, None)
    _replace(tmp, out_dir)


def _replace(new: Path, out_dir: Path) -> None:
    """Put folder ``new`` at ``out_dir``, removing what was there (two renames)."""
    old = None
    if out_dir.exists():
        old = Path(tempfile.mkdtemp(prefix=f".{out_dir.name}.old.", dir=out_dir.parent))
        os.replace(out_dir, old / "x")
    os.replace(new, out_dir)
    if old is not None:
        shutil.rmtree(old, ignore_errors=True)
