"""Random valid scenes (hypothesis draws the seed of ``random_scenes.draw_scene``): a scene
the checks before the work accept runs to the end; one they refuse is one line, exit 2,
nothing written. Never a traceback, and never an error after the work started.

"Accepted" is decided independently of the command: the scene is loaded and given to the
solver choice, the solver's own check and the run's cost estimate (which refuses sensors it
cannot replay), as ``tailbeam.simulate`` does before any work. The time against the estimate
is a benchmark's question (``benchmarks/fuzz_scenes.py``), not a test's.
"""

import os

import hypothesis
import hypothesis.strategies as st
import tomli_w
from random_scenes import draw_scene

from tailbeam.cli import main
from tailbeam.errors import InputError, WorkLimitError
from tailbeam.io.scene_file import loads_scene
from tailbeam.simulation import choose_solver
from tailbeam.solvers.base import Options
from tailbeam.solvers.run_cost import estimate_run

EXAMPLES = int(os.environ.get("TAILBEAM_PROPERTY_SCENES", "8"))


def refusal(text: str):
    """The checks before the work, as ``tailbeam.simulate`` makes them: None if they accept
    the scene, else the error they raise."""
    try:
        scene = loads_scene(text)
        method = choose_solver(scene)
        method.check(scene, Options())
        estimate_run(scene, method)
    except (InputError, WorkLimitError) as err:
        return err
    return None


@hypothesis.settings(
    max_examples=EXAMPLES,
    deadline=None,
    suppress_health_check=[hypothesis.HealthCheck.function_scoped_fixture],
)
@hypothesis.given(seed=st.integers(0, 2**31 - 1))
def test_a_valid_scene_runs_or_is_refused_up_front(seed, tmp_path_factory, capsys):
    text = tomli_w.dumps(draw_scene(seed))
    folder = tmp_path_factory.mktemp("scene")
    (folder / "scene.toml").write_text(text)
    out = folder / "out"
    code = main(["simulate", str(folder / "scene.toml"), "--out", str(out), "--quiet"])
    err = capsys.readouterr().err
    refused = refusal(text)
    assert "Traceback" not in err, err
    if refused is None:
        assert code == 0, f"seed {seed}: accepted up front, failed later: {err}"
        assert (out / "impacts.csv").is_file()
    else:
        assert code == 2 and err.count("\n") == 1, (seed, err)
        assert not out.exists()
