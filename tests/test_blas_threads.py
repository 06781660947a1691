"""``tailbeam.simulate`` holds BLAS to the thread limit of ``tailbeam.plate.blas`` while it
runs and gives the caller's limit back after it."""

import pytest
from threadpoolctl import threadpool_info, threadpool_limits

import tailbeam
from tailbeam.io.scene_file import loads_scene
from tailbeam.plate.blas import blas_threads
from tailbeam.simulation import SOLVERS

SCENE = """
duration = 0.01
[plate]
model = "rigid"
[[balls]]
name = "c"
material = "coal"
radius = 0.02
position = [0.0, 0.0, 0.05]
"""


def _blas_limits() -> list:
    return [pool["num_threads"] for pool in threadpool_info() if pool["user_api"] == "blas"]


@pytest.fixture
def seen(monkeypatch):
    """The BLAS thread counts while the single-ball solver runs."""
    solver, out = SOLVERS["single-ball"], []
    run = solver.run

    def spy(*args, **kwargs):
        out.append(_blas_limits())
        return run(*args, **kwargs)

    monkeypatch.setattr(solver, "run", spy)
    return out


def test_the_run_holds_blas_and_restores_the_callers_limit(seen, monkeypatch):
    if not _blas_limits():
        pytest.skip("no BLAS library reports its threads")
    monkeypatch.delenv("TAILBEAM_BLAS_THREADS", raising=False)
    with threadpool_limits(limits=2, user_api="blas"):
        before = _blas_limits()
        tailbeam.simulate(loads_scene(SCENE), progress=False)
        assert _blas_limits() == before
    assert seen == [[1] * len(before)]


def test_the_environment_sets_the_limit(seen, monkeypatch):
    if not _blas_limits():
        pytest.skip("no BLAS library reports its threads")
    monkeypatch.setenv("TAILBEAM_BLAS_THREADS", "2")
    assert blas_threads() == 2 and blas_threads(3) == 3
    with threadpool_limits(limits=1, user_api="blas"):
        tailbeam.simulate(loads_scene(SCENE), progress=False)
        assert set(_blas_limits()) == {1}
    assert seen == [[2] * len(seen[0])]
