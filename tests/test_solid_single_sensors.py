"""A single ball's plain sensors on a structure (``ModalReplay.sensor_outputs``): the
truncated modes' quasi-static part at each sensor from the sensor influences cached beside
the basis (tailbeam.plate.solid.face.influence), so a run whose sensors were solved before
assembles and factorises nothing.

Independent truth: the same replay on the basis without its model, whose residual cross
compliance is the direct static solve (K^-1 of the contact disc's own load vector, read at
the sensor: ``StructureModel.static_deflection``). Measured: the residual cross compliances
within 2.9e-12 of the full static compliance (the solves' round-off; held 1e-10), the signals
within 1.3e-10 and 8.2e-10 of their peaks (held: that relative error times the chain's
reading of the quasi-static part alone).
"""

import dataclasses

import numpy as np
import pytest
from solid_meshes import plate_mesh

from tailbeam.plate.solid import Support, assemble_structure, structure_modes
from tailbeam.signals.sensor import SensorSpec, measure
from tailbeam.solvers.coupled.replay import ModalReplay

FMAX = 1500.0  # Hz: a few modes, so the quasi-static part is a large share of the reading
CONTACT = (0.05, 0.0, 0.004)  # x, y, load radius (m) of the ball's contact
SENSORS = (SensorSpec("S1", (-0.1, 0.05)), SensorSpec("S2", (0.12, -0.07)))
DURATION = 0.003  # s
ROUND_OFF = 1e-10  # of the full static compliance: the static solves' round-off (measured 3e-12)


def _model(path):
    return assemble_structure(path, "top", [Support("clamped", group="sides")])


@pytest.fixture(scope="module")
def structure(tmp_path_factory):
    root = tmp_path_factory.mktemp("single_sensors")
    path = plate_mesh(root / "plate.msh", divisions=6)
    cache = root / "cache"
    return path, cache, structure_modes(_model(path), fmax_hz=FMAX, cache_dir=cache)


def _replay(basis) -> ModalReplay:
    """One contact: a 0.1 ms half-sine of 300 N peak at CONTACT, then no force."""
    x, y, r = CONTACT
    tn = np.concatenate([np.linspace(0.0, 1e-4, 11), [DURATION]])
    force = np.concatenate([300.0 * np.sin(np.linspace(0.0, np.pi, 11)), [0.0]])[:, None]
    nodes = (tn, np.zeros_like(force), np.zeros_like(force), force, np.zeros_like(force))
    phis = np.ascontiguousarray(basis.load_deflection([(x, y)], r)[None, :, :])
    zeta = np.full(basis.n_modes, 0.01)
    seg_phase = np.zeros(len(tn), dtype=np.int64)
    return ModalReplay(basis, zeta, nodes, seg_phase, phis, ((0.0, 0, x, y, r),), True)


def test_cached_influences_equal_the_direct_static_solve(structure):
    """The residual cross compliance is a small difference of the full static compliance
    and the kept modes' part: the solves' round-off is relative to the full one. The
    signals are linear in it: they differ by its relative error times the chain's reading
    of the quasi-static part alone."""
    _path, _cache, basis = structure
    direct = _replay(dataclasses.replace(basis, model=None))
    ours = _replay(basis)
    points = np.array([s.position for s in SENSORS])
    full = np.abs(basis.static_deflection_at(CONTACT[:2], points, CONTACT[2]))
    truth = direct._cross_compliance(*CONTACT, points)
    assert np.max(np.abs(ours._cross_compliance(*CONTACT, points) - truth)) <= ROUND_OFF * max(full)
    expect = direct.sensor_outputs(SENSORS, DURATION)
    signals = ours.sensor_outputs(SENSORS, DURATION)
    top = float(np.max(basis.frequencies_hz))
    for i, s in enumerate(SENSORS):
        alone = measure(s, lambda t, i=i: direct.quasi_static_sample(t, points)["a"][i],
                        DURATION, max_frequency_hz=top).acceleration  # fmt: skip
        bound = ROUND_OFF * full[i] / abs(truth[i]) * np.max(np.abs(alone))
        assert np.max(np.abs(signals[s.name].acceleration - expect[s.name].acceleration)) <= bound


def test_a_second_run_assembles_and_factorises_nothing(structure):
    path, cache, _basis = structure
    first = structure_modes(_model(path), fmax_hz=FMAX, cache_dir=cache)
    before = _replay(first).sensor_outputs(SENSORS, DURATION)  # the influences solved, kept
    assert len(list(cache.glob("structure-sensor-influence-*.npz"))) == len(SENSORS)
    fresh = _model(path)
    basis = structure_modes(fresh, fmax_hz=FMAX, cache_dir=cache)
    after = _replay(basis).sensor_outputs(SENSORS, DURATION)
    assert basis.info["cache"] == "hit"
    assert not fresh.assembled and fresh._solver is None
    for s in SENSORS:
        assert np.array_equal(after[s.name].acceleration, before[s.name].acceleration)
