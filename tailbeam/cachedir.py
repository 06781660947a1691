"""Where tailbeam keeps what it computes once: modal bases and numba's compiled kernels.

Both live under one folder, ``$TAILBEAM_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/tailbeam``
or ``~/.cache/tailbeam``: never inside the installed package, so reinstalling tailbeam (for
example ``pip install .`` then ``pip install -e .``) cannot leave stale files in
``site-packages/tailbeam`` that would shadow the new install.
"""

import hashlib
import os
import sys
import tempfile
from pathlib import Path

_PACKAGE = Path(__file__).resolve().parent


def cache_root() -> Path:
    """The folder for everything tailbeam caches (not created here)."""
    env = os.environ.get("TAILBEAM_CACHE_DIR")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME")
    base = Path(xdg) if xdg else Path.home() / ".cache"
    return base / "tailbeam"


def source_fingerprint() -> str:
    """A short hash of every tailbeam source file (names and contents, in a fixed order).

    numba checks a cached kernel against its own source file only: a kernel that calls (or
    inlines, or reads a constant of) a function edited in another module would load stale
    machine code. Keying the cache folder by the whole package's sources makes any change of
    tailbeam recompile every kernel once (~1 ms to compute at import)."""
    digest = hashlib.sha256()
    for path in sorted(_PACKAGE.rglob("*.py")):
        digest.update(path.relative_to(_PACKAGE).as_posix().encode())
        digest.update(path.read_bytes())
    return digest.hexdigest()[:16]


def numba_cache_dir() -> Path:
    """The folder of numba's compiled kernels: ``$NUMBA_CACHE_DIR`` if the user set it, else
    ``cache_root()/numba/<source_fingerprint()>``."""
    if os.environ.get("NUMBA_CACHE_DIR"):
        return Path(os.environ["NUMBA_CACHE_DIR"])
    return cache_root() / "numba" / source_fingerprint()


def configure_numba_cache() -> Path:
    """Point numba's on-disk cache at ``numba_cache_dir()`` unless the user chose one.

    Must run before any ``@njit(cache=True)`` function is defined; ``tailbeam/__init__``
    calls it first. Respects an explicit ``NUMBA_CACHE_DIR``.
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return Path(os.environ["NUMBA_CACHE_DIR"])
    folder = _writable(numba_cache_dir())
    if "numba" in sys.modules:  # numba read its environment already: set its config
        sys.modules["numba"].config.CACHE_DIR = str(folder)
    else:
        os.environ["NUMBA_CACHE_DIR"] = str(folder)
    return folder


def _writable(folder: Path) -> Path:
    """``folder``, created; if it cannot be, the same fingerprint's folder under the system's
    temporary folder, with a line on stderr saying why (numba, left with a folder it cannot
    write, would cache into the installed package instead)."""
    try:
        folder.mkdir(parents=True, exist_ok=True)
        return folder
    except OSError as err:
        spare = Path(tempfile.gettempdir()) / f"tailbeam-{os.getuid()}" / "numba" / folder.name
        sys.stderr.write(
            f"tailbeam: cannot create the cache folder {folder} ({err.strerror}); compiled "
            f"kernels go to {spare}: set TAILBEAM_CACHE_DIR to a writable folder\n"
        )
        spare.mkdir(parents=True, exist_ok=True)
        return spare


# First-run compile time of each solver's kernels, measured on the 2-core machine (examples
# two_balls_rigid, modal_plate, small_stream with an empty cache, minus a cached run)
COMPILE_SECONDS = {"rigid": "~10 s", "coupled": "~30 s", "stream": "~25 s"}
# The source folder of each solver's kernels (numba names its cache folders after it)
KERNEL_FOLDERS = {"rigid": "rigid", "coupled": "coupled", "stream": "compiled"}


def announce_first_compile(solver: str = "rigid") -> None:
    """Say so (tailbeam.progress.note) when numba's cache holds no compiled kernel of
    ``solver`` (``"rigid"``, ``"coupled"`` or ``"stream"``; numba names its cache folders after
    the kernels' source folder, ``KERNEL_FOLDERS``): the first run compiles them
    (COMPILE_SECONDS), later runs load them from the cache."""
    folder = Path(os.environ.get("NUMBA_CACHE_DIR") or numba_cache_dir())
    if not any(folder.glob(f"{KERNEL_FOLDERS.get(solver, solver)}*/*.nbi")):
        from tailbeam.progress import note

        took = COMPILE_SECONDS.get(solver, "10-30 s")
        note(f"first run: compiling the contact kernels with numba ({took}, cached in {folder})")
