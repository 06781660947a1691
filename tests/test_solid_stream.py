"""Streams on a structure from a mesh (``[[streams]]`` with ``[plate] mesh``): the stream
solvers take the structure's basis through the ModalBasis interface (shapes on the impact
face, static compliance for the residual flexibility).

- physics: the flat 0.6 x 0.6 x 0.01 m clamped plate as a solid mesh against the flat
  Mindlin plate (CCCC), the same two balls through the fast stream solver: every
  contact's restitution, peak force and duration within the solid-Mindlin difference the
  single-ball scene test holds (1.6 %), and the first landing (on the plate at rest) at the
  same time (free flight; the later ones meet each plate's own vibration);
- wiring: the fast stream solver on the structure's basis, at its default settings, against
  the slow reference (``simulate_stream_reference`` with the frozen-shape ReferencePlate, its
  own integrator): both integrate the same equations to rtol 1e-12, and they agree to 1e-9;
- a contact tail (``plate.tail = "ritz"``) on a structure is built from the same
  structure's modes to the tail's band.
"""

import numpy as np
import pytest
from solid_meshes import clamped_plate_scenes, plate_mesh
from test_stream_solver import _particles, _worst_difference

import tailbeam
from tailbeam import COAL, SANDSTONE, Ball
from tailbeam.io.scene_file import loads_scene
from tailbeam.physics.incline import InclinedPlate
from tailbeam.plate.solid import Support, assemble_structure, structure_modes
from tailbeam.solvers.stream.driver import loop as stream
from tailbeam.solvers.stream.plate import StreamPlate
from tailbeam.solvers.stream.reference.plate import ReferencePlate
from tailbeam.solvers.stream.reference.solver import simulate_stream_reference

FMAX = 1500.0  # Hz
ZETA = 0.01
SOLID_MINDLIN = 0.016  # tests/test_solid_scene.py: static compliance under the contact disc

STREAM = """
[[balls]]
name = "a"
material = "sandstone"
radius = 0.02
position = [0.05, 0.0, 0.0205]
velocity = [0.0, 0.0, -1.5]
[[balls]]
name = "b"
material = "coal"
radius = 0.025
position = [-0.12, 0.1, 0.03]
velocity = [0.0, 0.0, -1.0]
"""
STRUCTURE, FLAT = clamped_plate_scenes("plate.msh", 0.01, FMAX)


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    root = tmp_path_factory.mktemp("solid_stream")
    plate_mesh(root / "plate.msh", divisions=24)
    return root


def _stream_run(text, folder):
    scene = loads_scene(text + STREAM, base_dir=folder)
    return tailbeam.simulate(scene, solver="stream", progress=False)


def test_meshed_plate_stream_matches_the_mindlin_plate(folder):
    runs = {name: _stream_run(text, folder) for name, text in
            (("solid", STRUCTURE), ("flat", FLAT))}  # fmt: skip
    solid, flat = (sorted(runs[k].impacts, key=lambda r: r.ball) for k in ("solid", "flat"))
    assert [r.ball for r in solid] == [r.ball for r in flat] == ["a", "b"]
    assert runs["solid"].info["basis"]["theory"] == "solid"
    assert abs(solid[0].t_start - flat[0].t_start) < 1e-9  # "a" lands on the plate at rest
    for s, f in zip(solid, flat, strict=True):
        assert abs(s.restitution - f.restitution) < SOLID_MINDLIN * f.restitution
        assert abs(s.peak_force - f.peak_force) < SOLID_MINDLIN * f.peak_force
        duration = f.t_end - f.t_start
        assert abs((s.t_end - s.t_start) - duration) < SOLID_MINDLIN * duration


@pytest.fixture(scope="module")
def small_basis(tmp_path_factory):
    path = plate_mesh(tmp_path_factory.mktemp("solid_stream_small") / "p.msh", divisions=8)
    model = assemble_structure(path, "top", [Support("clamped", group="sides")])
    return structure_modes(model, fmax_hz=FMAX)


def test_fast_stream_matches_the_reference_on_a_structure(small_basis):
    """Two balls (one landing beside the other's spot, so the second meets a vibrating
    plate) on the structure, no residual flexibility: the fast solver at its defaults against
    the frozen-shape reference, every Impact field within 1e-9 (relative; times on 1 ms).
    Both land vertically on the level plate, so no contact point travels and the shapes are
    never refreshed: the fast solver's shape refresh (every 1 mm of travel by default, 1 um
    measured alike) plays no part, and what is left is the two integrators' tolerance,
    measured 3.2e-11 (the coal ball's rebound speed)."""
    balls = [Ball("s", SANDSTONE, 0.02, (0.03, 0.02, 0.0201), (0.0, 0.0, -1.5)),
             Ball("k", COAL, 0.02, (-0.05, -0.04, 0.03), (0.0, 0.0, -1.0))]  # fmt: skip
    incline = InclinedPlate()
    duration = 0.012
    ref = simulate_stream_reference(balls, incline, duration,
                                    plate=ReferencePlate(small_basis, ZETA, "frozen"))  # fmt: skip
    plate = StreamPlate(small_basis, np.full(small_basis.n_modes, ZETA),
                        residual_flexibility=False)  # fmt: skip
    fast = stream.solve_stream(_particles(balls), incline, duration, rtol=1e-12,
                               rest_speed=0.0, progress=False, plate=plate)  # fmt: skip
    assert len(ref.contacts) == 2
    assert _worst_difference(ref.contacts, fast.contacts) < 1e-9


def test_ritz_contact_tail_on_a_structure_uses_its_own_modes(tmp_path):
    """plate.tail = "ritz" on a stream: the tails' basis is the same structure's modes to
    the tails' band (4x the band), whose modes below the band are the band's (to 1e-9)."""
    from tailbeam.plate.solid.modes import StructureModalBasis
    from tailbeam.solvers.modal_setup.setup import stream_setup

    plate_mesh(tmp_path / "plate.msh", divisions=8)
    text = STRUCTURE.replace(
        'tail = "quasi-static"', 'tail = "ritz"\ntail_modes = 2\ninclination = 10.0'
    )  # inclined: the stream solver's scene
    scene = loads_scene(text + STREAM, base_dir=tmp_path)
    setup = stream_setup(scene)
    wide, band = setup.contact_tail.wide, setup.basis
    assert isinstance(wide, StructureModalBasis) and wide.model is band.model
    assert wide.frequencies_hz[-1] <= setup.band["tail_band_hz"] < 1.01 * 4 * FMAX
    assert wide.n_modes > band.n_modes
    low = wide.frequencies_hz[: band.n_modes]
    assert np.allclose(low, band.frequencies_hz, rtol=1e-9, atol=0)
