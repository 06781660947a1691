"""Any linear elastic structure from a volume mesh: the mesh and its named groups
(``volume_mesh``), quadratic solid elements (``elasticity``), supports (``supports``), the
impact face, fast readings and the static compliance on it (the ``face`` subpackage), the
outer surface and readings anywhere on it (``surface``, ``probe``), the assembled structure
(``model``) and its modes as a ``ModalBasis`` (``modes``).

    from tailbeam.plate.solid import Support, assemble_structure, structure_modes
"""

from tailbeam.plate.solid.model import StructureModel, assemble_structure
from tailbeam.plate.solid.modes import StructureModalBasis, structure_modes
from tailbeam.plate.solid.supports import Support
from tailbeam.plate.solid.volume_mesh import VolumeMesh, read_volume_mesh

__all__ = [
    "Support",
    "StructureModel",
    "StructureModalBasis",
    "VolumeMesh",
    "assemble_structure",
    "read_volume_mesh",
    "structure_modes",
]
