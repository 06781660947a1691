"""A structure's sensor channels under loads on its impact face, by reciprocity from one
static solve per channel kept in the cache (tailbeam.plate.solid.face.influence), and the
stream replay that reads all channels in one march.

Independent truths: the direct static solve (K^-1 of the load's own vector, read by the
channel's operator; measured 2.8e-12 of the largest reading, the solves' round-off; held
1e-10); the replay of the plain points through the basis' own deflection and the direct
static solves (the basis without its model; measured within 1.3e-14 of the response; held
1e-11); and the cache's own file, read back without a factorisation.
"""

import dataclasses

import numpy as np
import pytest
from solid_meshes import plate_mesh

from tailbeam.plate.solid import Support, assemble_structure, structure_modes
from tailbeam.plate.solid.face.influence import FaceInfluence, influence_key
from tailbeam.signals.sensor import SensorSpec, measure
from tailbeam.solvers.plate_loads.loads import PlateLoads
from tailbeam.solvers.plate_loads.readings import Readings
from tailbeam.solvers.plate_loads.response import plate_response, sensor_outputs

H = 0.01  # m, the test plate's thickness (top face z = 0, bottom z = -H)
FMAX = 1500.0  # Hz: a few modes, so the quasi-static part is a large share of the reading
POINTS = np.array([[-0.1, 0.05, 0.0], [0.12, -0.07, -H], [0.03, 0.2, -H]])
DIRECTIONS = np.array([[0.0, 0.0, 1.0], [0.0, 0.0, 1.0], [1.0, -2.0, 3.0]]) / [[1], [1], [14**0.5]]
LOADS = np.array([[0.05, 0.0], [-0.2, 0.17], [0.21, -0.23], [0.0, 0.0]])


def _model(path):
    return assemble_structure(path, "top", [Support("clamped", group="sides")])


@pytest.fixture(scope="module")
def structure(tmp_path_factory):
    root = tmp_path_factory.mktemp("influence")
    path = plate_mesh(root / "plate.msh", divisions=6)
    model = _model(path)
    return path, model, structure_modes(model, fmax_hz=FMAX, cache_dir=root / "cache")


def _direct(model, operator, loads):
    """(q, p): each channel's reading under K^-1 of each load's own vector."""
    rhs = np.column_stack([model.load_vector(q) for q in loads])
    return np.asarray(operator @ model.solver().solve(rhs)).T


def test_reciprocity_equals_the_direct_static_solve(structure):
    _path, model, _basis = structure
    operator = model.surface_operator(POINTS, DIRECTIONS)
    ours = FaceInfluence(model, operator, POINTS, DIRECTIONS)(LOADS)
    truth = _direct(model, operator, LOADS)
    assert np.max(np.abs(ours - truth)) <= 1e-10 * np.max(np.abs(truth))


def test_the_cache_gives_the_same_vectors_without_a_factorisation(structure, tmp_path):
    path, model, _basis = structure
    operator = model.surface_operator(POINTS, DIRECTIONS)
    first = FaceInfluence(model, operator, POINTS, DIRECTIONS, tmp_path)
    assert len(list(tmp_path.glob("structure-sensor-influence-*.npz"))) == len(POINTS)
    fresh = _model(path)  # a new model object: no factorisation in it
    again = FaceInfluence(fresh, operator, POINTS, DIRECTIONS, tmp_path)
    assert fresh._solver is None
    assert np.array_equal(again.vectors, first.vectors)
    assert np.array_equal(again(LOADS), first(LOADS))


def test_a_damaged_file_is_said_and_recomputed(structure, tmp_path, capsys):
    _path, model, _basis = structure
    operator = model.surface_operator(POINTS, DIRECTIONS)
    first = FaceInfluence(model, operator, POINTS, DIRECTIONS, tmp_path)
    damaged = sorted(tmp_path.glob("structure-sensor-influence-*.npz"))[0]
    damaged.write_bytes(b"not a zip file")
    capsys.readouterr()
    again = FaceInfluence(model, operator, POINTS, DIRECTIONS, tmp_path)
    assert "is damaged" in capsys.readouterr().err
    scale = np.max(np.abs(first.vectors))
    assert np.max(np.abs(again.vectors - first.vectors)) <= 1e-12 * scale
    assert np.array_equal(FaceInfluence(model, operator, POINTS, DIRECTIONS, tmp_path).vectors,
                          again.vectors)  # fmt: skip


def test_the_key_tells_channels_apart(structure):
    _path, model, _basis = structure
    directions = np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], DIRECTIONS[2]])
    keys = {influence_key(model, p, d) for p in POINTS for d in directions}
    assert len(keys) == len(POINTS) * len(directions)


def _loads():
    loads = PlateLoads()
    loads.add_contact(0.05, 0.0, np.linspace(0.0, 1e-4, 9), 300 * np.sin(np.linspace(0, np.pi, 9)))
    loads.add_contact(-0.2, 0.17, np.linspace(3e-4, 5e-4, 7), 80 * np.sin(np.linspace(0, np.pi, 7)))
    return loads


def test_one_replay_of_all_channels_equals_the_direct_path(structure):
    """All channels in one march, the load shapes from the fast face readings and the static
    part from the cached influences: the same plate response at the plain points as the
    basis' own deflection with a direct static solve per point (the basis without its
    model: the path a flat plate takes), to round-off of the response (quasi-static part
    included), and the same sensor signals."""
    _path, _model_, basis = structure
    direct = dataclasses.replace(basis, model=None)
    zeta = np.full(basis.n_modes, 0.01)
    times = np.arange(2000) / 200000.0
    xy = np.array([[-0.1, 0.05], [0.12, -0.07]])
    truth = plate_response(direct, zeta, _loads(), xy, times)
    sensors = [SensorSpec("S1", tuple(xy[0])), SensorSpec("S2", tuple(xy[1])),
               SensorSpec("back", tuple(POINTS[2]), direction=tuple(DIRECTIONS[2]))]  # fmt: skip
    channels = [c for s in sensors for c in s.channels()]
    ours = plate_response(basis, zeta, _loads(), None, times, readings=Readings(basis, channels))
    for key in ("w", "v", "a"):
        scale = np.max(np.abs(truth[key]))
        assert np.max(np.abs(ours[key][:2] - truth[key])) <= 1e-11 * scale
    outputs = sensor_outputs(basis, zeta, _loads(), sensors, 0.004)
    top = float(np.max(basis.frequencies_hz))
    for i, spec in enumerate(sensors[:2]):
        expect = measure(spec, lambda t, i=i: plate_response(direct, zeta, _loads(), xy, t)["a"][i],
                         0.004, max_frequency_hz=top).acceleration  # fmt: skip
        got = outputs[spec.name].acceleration
        assert np.max(np.abs(got - expect)) <= 1e-11 * np.max(np.abs(expect))
