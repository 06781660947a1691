"""A structure's modes for ParaView: the volume mesh with each mode's displacement vector.

``write_modes_vtu`` writes the mesh's cells (corner nodes, in VTK's node order by
scikit-fem's own meshio converter), one point field ``mode_NNN_<f>Hz`` per mode (the
displacement vector, 1/sqrt(kg); ParaView's 'Warp By Vector' shows the shape) and the
frequencies (Hz) as the field data ``frequencies_hz``.
"""

from pathlib import Path

import numpy as np


def mode_field_names(frequencies_hz) -> list:
    """'mode_001_32.9Hz', ...: one name per mode, zero-padded to the count's width."""
    width = max(3, len(str(len(frequencies_hz))))
    return [f"mode_{i + 1:0{width}d}_{f:.1f}Hz" for i, f in enumerate(frequencies_hz)]


def write_modes_vtu(path, basis) -> Path:
    """Write the StructureModalBasis ``basis`` to ``path`` (.vtu, see module docstring)."""
    import meshio
    from skfem.io.meshio import to_meshio

    out = to_meshio(basis.model.vmesh.mesh)  # points: the mesh's nodes, in order
    shapes = basis.nodal_displacements()
    names = mode_field_names(basis.frequencies_hz)
    fields = {name: np.ascontiguousarray(shapes[:, :, i]) for i, name in enumerate(names)}
    mesh = meshio.Mesh(
        out.points,
        out.cells,
        point_data=fields,
    )
    meshio.write(Path(path), mesh, file_format="vtu")
    _add_field_data(Path(path), "frequencies_hz", basis.frequencies_hz)
    return Path(path)


def _add_field_data(path: Path, name: str, values) -> None:
    """Insert a Float64 FieldData array (ASCII, every digit of each value) into the VTU file
    ``path``: meshio reads VTU field data but does not write it."""
    text = " ".join(repr(float(v)) for v in values)
    block = (
        f'<FieldData><DataArray type="Float64" Name="{name}" NumberOfTuples="{len(values)}" '
        f'format="ascii">{text}</DataArray></FieldData>'
    )
    data = path.read_bytes()
    tag = b"<UnstructuredGrid>"
    at = data.index(tag) + len(tag)
    path.write_bytes(data[:at] + block.encode() + data[at:])


__all__ = ["mode_field_names", "write_modes_vtu"]
