"""The estimate of a structure's eigen-solve (tailbeam.plate.solid.cost), piece by piece,
against independent counts on small meshes: the volume and area against the box's closed
form, the Weyl-type mode count against the flat plate's closed-form wavenumber and against
Sylvester's exact count, the factor's entries and bytes against the factor SuperLU builds,
the shift-invert solves against those ARPACK asks for; and a structure scene's cost line
estimates the eigen-solve. No timings (benchmarks/bench_cost_model.py --solid has them)."""

import math

import pytest
from solid_meshes import box_beam_mesh, plate_mesh

from tailbeam.io.scene_file import loads_scene
from tailbeam.physics.bodies import Plate
from tailbeam.physics.materials import CARBON_STEEL
from tailbeam.plate.closed_forms import bending_wavenumber
from tailbeam.plate.fe.sparse_solve import count_eigenvalues_below
from tailbeam.plate.solid import Support, assemble_structure
from tailbeam.plate.solid import cost as C
from tailbeam.plate.solid import modes as solid_modes
from tailbeam.plate.solid.factor import factorize
from tailbeam.simulation import choose_solver, simulate
from tailbeam.solvers.modal_setup.plan import plan_bases
from tailbeam.solvers.run_cost import estimate_run

SIDE, THICK = 0.6, 0.01
STRUCTURE_SCENE = """duration = 0.002
[plate]
model = "modal"
mesh = "plate.msh"
impact_face = "top"
fmax = 3000.0
tail = "quasi-static"
[[plate.supports]]
group = "sides"
kind = "clamped"
[[balls]]
name = "b"
material = "sandstone"
radius = 0.03
position = [0.05, 0.0, 0.0305]
velocity = [0.0, 0.0, -2.0]
"""


@pytest.fixture(scope="module")
def plate(tmp_path_factory):
    """The clamped 0.6 x 0.6 x 0.01 m steel plate, 12 x 12 x 1 hexahedra."""
    path = plate_mesh(str(tmp_path_factory.mktemp("m") / "plate.msh"), divisions=12)
    return assemble_structure(path, "top", (Support(kind="clamped", group="sides"),))


@pytest.fixture(scope="module")
def box(tmp_path_factory):
    """A 2 m box beam, 0.15 x 0.1 m, 10 mm walls, clamped at its root."""
    path = box_beam_mesh(str(tmp_path_factory.mktemp("m") / "box.msh"), 2.0, 0.15, 0.1, 0.01, 20)
    return assemble_structure(path, "top", (Support(kind="clamped", group="root"),))


def test_volume_and_area_of_the_plate_mesh(plate):
    volume, area = C.mesh_volume_area(plate.vmesh.mesh)
    assert volume == pytest.approx(SIDE * SIDE * THICK, rel=1e-12)
    assert area == pytest.approx(2 * SIDE * SIDE + 4 * SIDE * THICK, rel=1e-12)


def test_thin_wall_count_is_the_plates_weyl_term():
    # a thin plate's leading flexural count is A k^2 / (4 pi), k its Kirchhoff wavenumber
    volume, area = SIDE * SIDE * THICK, 2 * SIDE * SIDE  # the faces only: h, A exact
    flat = Plate(material=CARBON_STEEL, size_x=SIDE, size_y=SIDE, thickness=THICK)
    for f in (1000.0, 4000.0):
        k = float(bending_wavenumber(flat, f, "kirchhoff"))
        flexural = SIDE * SIDE * k * k / (4 * math.pi)
        count = C.modes_below(volume, area, CARBON_STEEL, f)
        # the in-plane waves add a few percent at these bands
        assert flexural <= count <= 1.1 * flexural + 1


@pytest.mark.parametrize("which, fmax", [("plate", 3000.0), ("box", 2000.0)])
def test_count_is_high_but_within_twice_the_exact_count(which, fmax, plate, box):
    model = {"plate": plate, "box": box}[which]
    exact = count_eigenvalues_below(model.stiffness, model.mass, (2 * math.pi * fmax) ** 2,
                                    factorize)  # fmt: skip
    estimate = C.structure_cost(model, fmax).n_modes
    assert exact <= estimate <= 2.1 * exact


def test_factor_entries_and_bytes_against_the_factor(plate, box):
    for model in (plate, box):
        lu = factorize(model.stiffness)._lu
        entries = lu.L.nnz + lu.U.nnz
        estimate = C.factor_entries(model.n_dofs, model.stiffness.nnz)
        assert 0.7 * entries <= estimate <= 1.3 * entries
        held = sum(m.data.nbytes + m.indices.nbytes for m in (lu.L, lu.U))
        assert held == pytest.approx(C.FACTOR_BYTES * entries, rel=0.01)


def test_solves_against_arpacks(plate, monkeypatch):
    fmax = 3000.0
    calls = []
    monkeypatch.setattr(solid_modes, "lowest_modes", _counting(solid_modes.lowest_modes, calls))
    freqs, _ = solid_modes.solve_band(plate, fmax)
    nev = len(freqs) + plate.rigid_modes + solid_modes.MARGIN
    predicted = C.solve_cost(plate.n_dofs, plate.stiffness.nnz, len(freqs),
                             plate.rigid_modes + solid_modes.MARGIN).solves  # fmt: skip
    # ARPACK's count moves by whole restarts with round-off (BLAS threads, what ran before in
    # the process: 57 and 73 solves for this plate); a restart applies the operator up to
    # ncv - nev times
    restart = min(plate.n_dofs, int(1.5 * nev) + 20) - nev
    assert abs(predicted - calls[0]) <= restart


def _counting(lowest_modes, calls):
    def wrapped(*args, on_solve=None, **kwargs):
        calls.append(0)

        def counted(n):
            calls[0] += n

        return lowest_modes(*args, on_solve=counted, **kwargs)

    return wrapped


def test_memory_holds_the_factor_and_the_lanczos_vectors():
    small = C.solve_cost(10_000, 1_000_000, 50)
    more_modes = C.solve_cost(10_000, 1_000_000, 150)
    # 100 more modes: 150 more Lanczos vectors and 200 more returned columns of 8 bytes
    extra = more_modes.memory_bytes - small.memory_bytes
    assert extra == pytest.approx(8.0 * 10_000 * (150 + 200), rel=1e-12)


def test_a_structure_scenes_cost_line_estimates_its_eigen_solve(tmp_path, monkeypatch):
    plate_mesh(str(tmp_path / "plate.msh"), divisions=12)
    monkeypatch.chdir(tmp_path)
    scene = loads_scene(STRUCTURE_SCENE)
    cost = estimate_run(scene, choose_solver(scene, "auto"))
    eigen = cost.part("eigen-solve")
    assert eigen.estimated and eigen.time_s > 0 and "factor entries" in eigen.driver
    assert "not estimated" not in cost.describe()


def test_a_cached_structure_is_costed_as_its_reading(tmp_path, monkeypatch):
    """Once the structure's basis is in the cache the eigen-solve part is the file's reading,
    with the cached basis' own mode count (its vectors' columns)."""
    plate_mesh(str(tmp_path / "plate.msh"), divisions=12)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("TAILBEAM_CACHE_DIR", str(tmp_path / "cache"))
    scene = loads_scene(STRUCTURE_SCENE)
    solver = choose_solver(scene, "auto")
    assert not estimate_run(scene, solver).part("eigen-solve").cached
    model = assemble_structure("plate.msh", "top", (Support(kind="clamped", group="sides"),))
    basis = solid_modes.structure_modes(model, fmax_hz=3000.0)
    eigen = estimate_run(scene, solver).part("eigen-solve")
    assert eigen.cached and "cached" in eigen.driver
    assert plan_bases(scene, stream=False).n_modes == len(basis.frequencies_hz)


def test_a_three_axis_sensor_costs_as_three_sensors(tmp_path, monkeypatch):
    """Replay and writing count signals: a sensor with axes = "xyz" as three along x, y, z."""
    plate_mesh(str(tmp_path / "plate.msh"), divisions=12)
    monkeypatch.chdir(tmp_path)
    point = "position = [-0.1, 0.05, -0.01]\nsample_rate = 25600.0\n"
    three_axis = f'[[sensors]]\nname = "back"\n{point}axes = "xyz"\n'
    units = {"x": "[1, 0, 0]", "y": "[0, 1, 0]", "z": "[0, 0, 1]"}
    three = "".join(
        f'[[sensors]]\nname = "{a}"\n{point}direction = {d}\n' for a, d in units.items()
    )
    costs = []
    for sensors in (three_axis, three):
        scene = loads_scene(STRUCTURE_SCENE + sensors)
        costs.append(estimate_run(scene, choose_solver(scene, "auto")))
    for part in ("sensor replay", "writing"):
        assert costs[0].part(part).time_s == costs[1].part(part).time_s


def test_the_static_set_up_is_costed_as_cached_once_the_run_cached_it(tmp_path, monkeypatch):
    """The set-up part is one factorisation of K until a run has left the impact face's
    compliance and every sensor channel's influence in the cache; then it is their reading
    (no time). A sensor the cache has not seen brings the factorisation back."""
    plate_mesh(str(tmp_path / "plate.msh"), divisions=12)
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("TAILBEAM_CACHE_DIR", str(tmp_path / "cache"))
    one = '[[sensors]]\nname = "S1"\nposition = [-0.1, 0.05]\nsample_rate = 25600.0\n'
    two = one + '[[sensors]]\nname = "S2"\nposition = [0.1, -0.05]\nsample_rate = 25600.0\n'
    scene = loads_scene(STRUCTURE_SCENE + one)
    solver = choose_solver(scene, "auto")
    before = estimate_run(scene, solver).part("set-up")
    assert not before.cached and before.time_s > 0 and "factorisation" in before.driver
    assert simulate(scene, progress=False).sensor_outputs  # solves, caches the static parts
    after = estimate_run(scene, solver).part("set-up")
    assert after.cached and after.time_s == 0.0
    scene_two = loads_scene(STRUCTURE_SCENE + two)
    assert not estimate_run(scene_two, choose_solver(scene_two, "auto")).part("set-up").cached
