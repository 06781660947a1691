"""What starting tailbeam imports: the package and the command line's parser load none of the
machinery (the solvers, numba, scipy's optimize/special/sparse, scikit-fem), the facade's names
load on first use and are the modules' own, and reading a scene on a structure (what
``tailbeam modes SCENE`` does) loads no solver and no numba (scikit-fem, scipy.sparse and, for
a stream's draws, scipy.special it needs).

Each check runs in a fresh interpreter (``sys.modules`` of this process holds whatever earlier
tests imported) and prints what it found as JSON.
"""

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]

# modules the start must not load: the compiled kernels' compiler, the heavy scipy parts,
# the finite-element library, and tailbeam's own machinery
HEAVY = (
    "numba",
    "scipy.optimize",
    "scipy.special",
    "scipy.sparse",
    "scipy.integrate",
    "skfem",
    "tailbeam.solvers",
    "tailbeam.simulation",
    "tailbeam.scene",
    "tailbeam.streams",
)

REPORT = """
import json, sys
HEAVY = {heavy!r}
def loaded():
    return sorted(m for m in sys.modules if any(m == h or m.startswith(h + ".") for h in HEAVY))
{code}
"""


def run_fresh(code: str) -> dict:
    """Run ``code`` (which prints one JSON line last) in a fresh interpreter on this tree."""
    source = REPORT.format(heavy=HEAVY, code=code)
    done = subprocess.run([sys.executable, "-c", source], capture_output=True, text=True,
                          cwd=ROOT, check=False)  # fmt: skip
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.splitlines()[-1])


def test_import_and_parser_load_no_machinery_and_the_facade_loads_on_use():
    found = run_fresh(
        """
import pydoc
import tailbeam
after_import = loaded()
from tailbeam.cli.main import build_parser
build_parser()
after_parser = loaded()
simulate = tailbeam.simulate
import tailbeam.simulation
from tailbeam import *
own = {}
for name in tailbeam.__all__:
    obj = getattr(tailbeam, name)
    if hasattr(obj, "__module__") and hasattr(obj, "__qualname__"):
        own[name] = obj.__name__ == name and getattr(sys.modules[obj.__module__], name) is obj
print(json.dumps({
    "after_import": after_import,
    "after_parser": after_parser,
    "same_simulate": simulate is tailbeam.simulation.simulate,
    "star": sorted(n for n in tailbeam.__all__ if n in globals()),
    "all": sorted(tailbeam.__all__),
    "own": own,
    "dir_has_all": set(tailbeam.__all__) <= set(dir(tailbeam)),
    "help": pydoc.render_doc(tailbeam, renderer=pydoc.plaintext),
    "after_use": loaded(),
}))
"""
    )
    assert found["after_import"] == []
    assert found["after_parser"] == []
    assert found["same_simulate"]
    assert found["star"] == found["all"] and len(found["all"]) == 20
    assert len(found["own"]) >= 12 and all(found["own"].values()), found["own"]
    assert found["dir_has_all"]
    assert "simulate(" in found["help"] and "class Ball" in found["help"]
    assert "numba" in found["after_use"] and "tailbeam.solvers" in found["after_use"]


def test_a_scene_on_a_structure_is_read_without_solvers_or_numba():
    """What ``tailbeam modes SCENE`` runs before reading the basis: the example beam's scene
    (streams, sensors, supports) read and checked; a force then evaluated loads numba."""
    scene = ROOT / "examples" / "tail_beam_stream.toml"
    found = run_fresh(
        f"""
from tailbeam import load_scene
scene = load_scene({str(scene)!r})
read = loaded()
law = scene.contacts().law(0, "plate")
print(json.dumps({{"read": read, "streams": len(scene.streams), "mesh": str(scene.modal.mesh),
                  "force": float(law.force(1e-6, 0.0)), "k": law.stiffness,
                  "e": law.exponent, "after_force": loaded()}}))
"""
    )
    assert found["streams"] == 1 and found["mesh"].endswith("tail_beam.msh")
    machinery = ("numba", "tailbeam.solvers", "tailbeam.simulation", "scipy.optimize",
                 "scipy.integrate")  # fmt: skip
    assert [m for m in found["read"] if m.startswith(machinery)] == []
    assert "skfem" in found["read"]  # the structure's checks need its elements: loaded here
    hertz = found["k"] * 1e-6 ** found["e"]  # at rest: the elastic term alone
    assert found["force"] == pytest.approx(hertz, rel=1e-14)
    assert "numba" in found["after_force"]
