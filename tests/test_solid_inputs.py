"""Bad structures and readings are refused in one line naming the field as the user writes
it (plate.mesh, plate.impact_face, plate.supports[i].group, sensors[i].position), before any
eigen-solve."""

import numpy as np
import pytest
from solid_meshes import plate_mesh

from tailbeam.errors import InputError
from tailbeam.plate.solid import Support, assemble_structure, read_volume_mesh, structure_modes


@pytest.fixture(scope="module")
def small_plate(tmp_path_factory):
    return plate_mesh(tmp_path_factory.mktemp("inputs") / "plate.msh", divisions=3)


def _refused(field, call, *args, **kwargs):
    with pytest.raises(InputError) as err:
        call(*args, **kwargs)
    assert err.value.field == field
    assert "\n" not in str(err.value)
    return str(err.value)


def test_named_groups_are_read(small_plate):
    vmesh = read_volume_mesh(small_plate)
    assert set(vmesh.faces) == {"top", "sides", "bottom"}
    mesh = vmesh.mesh
    top_z = mesh.p[2, mesh.facets[:, vmesh.faces["top"]]]
    assert len(vmesh.faces["top"]) == 9 and np.all(top_z == 0.0)
    assert len(vmesh.faces["sides"]) == 12


def test_impact_face_missing_or_not_flat_at_z0(small_plate):
    said = _refused("plate.impact_face", assemble_structure, small_plate, "roof",
                    [Support("clamped", group="sides")])  # fmt: skip
    assert "'roof'" in said and "top" in said
    said = _refused("plate.impact_face", assemble_structure, small_plate, "bottom",
                    [Support("clamped", group="sides")])  # fmt: skip
    assert "z = 0" in said
    _refused("plate.impact_face", assemble_structure, small_plate, "sides")


def test_support_group_missing(small_plate):
    supports = [Support("clamped", group="sides"), Support("pinned", group="hinge")]
    said = _refused("plate.supports[2].group", assemble_structure, small_plate, "top", supports)
    assert "'hinge'" in said
    _refused("plate.supports[1].region", assemble_structure, small_plate, "top",
             [Support("clamped", region=[[5, 6], [0, 1], [0, 1]])])  # fmt: skip
    _refused("plate.supports[1].stiffness", assemble_structure, small_plate, "top",
             [Support("spring", group="bottom")])  # fmt: skip


def test_unheld_structure(small_plate):
    said = _refused("plate.supports", assemble_structure, small_plate, "top", [])
    assert "6 rigid-body" in said and "free structure" in said
    # a spring along the bottom's normal holds z, and the rotations about x and y only
    said = _refused("plate.supports", assemble_structure, small_plate, "top",
                    [Support("spring", group="bottom", stiffness=1e6)])  # fmt: skip
    assert "3 rigid-body" in said
    assert assemble_structure(small_plate, "top", [], free=True).rigid_modes == 6


def test_sensor_off_the_surface(small_plate):
    model = assemble_structure(small_plate, "top", [Support("clamped", group="sides")])
    basis = structure_modes(model, count=3)
    inside = [[0.0, 0.0, -0.005]]  # mid-thickness: 5 mm from both faces
    said = _refused("sensors[1].position", basis.shape_at, inside, field_name="sensors[1].position")
    assert "not on the structure's surface" in said
    assert basis.shape_at([[0.1, 0.1, -0.01]]).shape == (1, 3)  # on the bottom: fine


def test_unreadable_or_flat_mesh(tmp_path):
    bad = tmp_path / "bad.msh"
    bad.write_text("$MeshFormat\nnot a mesh\n")
    said = _refused("plate.mesh", read_volume_mesh, bad)
    assert "cannot read" in said
    _refused("plate.mesh", read_volume_mesh, tmp_path / "absent.msh")
    from tailbeam.plate.fe.mesh import MESH_DIR

    said = _refused("plate.mesh", read_volume_mesh, MESH_DIR / "plate_0.6x0.6_6x6.msh")
    assert "volume mesh" in said


def test_region_support_is_the_group_it_covers(small_plate):
    """A box region around the side faces selects the same facets as the 'sides' group:
    the same model, frequencies equal to round-off."""
    by_group = assemble_structure(small_plate, "top", [Support("clamped", group="sides")])
    # one thin box around each side face (1 mm deep into the plate: no top or bottom face
    # lies wholly inside it)
    z = [-0.011, 0.001]
    boxes = ([[-0.31, -0.299], [-0.31, 0.31], z], [[0.299, 0.31], [-0.31, 0.31], z],
             [[-0.31, 0.31], [-0.31, -0.299], z], [[-0.31, 0.31], [0.299, 0.31], z])  # fmt: skip
    sides = [Support("clamped", region=box) for box in boxes]
    by_region = assemble_structure(small_plate, "top", sides)
    assert by_region.n_dofs == by_group.n_dofs
    f_group = structure_modes(by_group, count=4).frequencies_hz
    f_region = structure_modes(by_region, count=4).frequencies_hz
    assert np.allclose(f_region, f_group, rtol=1e-12, atol=0)


def test_tetrahedral_mesh_groups_are_read(tmp_path):
    from solid_meshes import tet_plate_mesh

    vmesh = read_volume_mesh(tet_plate_mesh(tmp_path / "tet.msh", divisions=3))
    assert vmesh.kind == "tetra"
    # 3 x 3 grid cells, each face cut in two triangles
    assert len(vmesh.faces["top"]) == 18 and len(vmesh.faces["sides"]) == 24
