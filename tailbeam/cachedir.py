"""Where tailbeam keeps what it computes once: modal bases and numba's compiled kernels.

Both live under one folder, ``$TAILBEAM_CACHE_DIR`` if set, else ``$XDG_CACHE_HOME/tailbeam``
or ``~/.cache/tailbeam``: never inside the installed package, so reinstalling tailbeam (for
example ``pip install .`` then ``pip install -e .``) cannot leave stale files in
``site-packages/tailbeam`` that would shadow the new install.
"""

import os
import sys
from pathlib import Path


def cache_root() -> Path:
    """The folder for everything tailbeam caches (not created here)."""
    env = os.environ.get("TAILBEAM_CACHE_DIR")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME")
    base = Path(xdg) if xdg else Path.home() / ".cache"
    return base / "tailbeam"


def configure_numba_cache() -> Path:
    """Point numba's on-disk cache at ``cache_root()/numba`` unless the user chose one.

    Must run before any ``@njit(cache=True)`` function is defined; ``tailbeam/__init__``
    calls it first. Respects an explicit ``NUMBA_CACHE_DIR``.
    """
    if os.environ.get("NUMBA_CACHE_DIR"):
        return Path(os.environ["NUMBA_CACHE_DIR"])
    folder = cache_root() / "numba"
    if "numba" in sys.modules:  # numba read its environment already: set its config
        sys.modules["numba"].config.CACHE_DIR = str(folder)
    else:
        os.environ["NUMBA_CACHE_DIR"] = str(folder)
    return folder


def announce_first_compile(solver: str = "rigid") -> None:
    """Say so (tailbeam.progress.note) when numba's cache holds no compiled kernel of
    ``solver`` (``"rigid"`` or ``"coupled"``, numba names its cache folders after the source
    folder): the first run compiles them (10-20 s), later runs load them from the cache."""
    folder = Path(os.environ.get("NUMBA_CACHE_DIR") or cache_root() / "numba")
    if not any(folder.glob(f"{solver}*/*.nbi")):
        from tailbeam.progress import note

        note(f"first run: compiling the contact kernels with numba (10-20 s, cached in {folder})")
