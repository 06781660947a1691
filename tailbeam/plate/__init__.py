"""The plate's modal model: the basis every solver takes (``basis``: natural frequencies,
unit-modal-mass mode shapes, modal damping), closed forms and published tables (``closed_forms``),
the finite-element model (``fe``: Kirchhoff/Argyris, Reissner-Mindlin/Lagrange P4, with
automatic theory and mesh choice), the disk cache (``cache``), the residual compliance of the
truncated modes (``compliance``) and the tails that stand in for them at a contact
(``ritz_tail``, ``contact_tail``).

    from tailbeam.plate import compute_modes, PlateModel, assemble_plate
"""

from tailbeam.plate.fe.boundary import parse_boundary, rigid_body_mode_count
from tailbeam.plate.fe.mesh import load_mesh, save_mesh, structured_mesh
from tailbeam.plate.fe.model import PlateModel, assemble_plate
from tailbeam.plate.fe.modes import FEModalBasis, compute_modes

__all__ = [
    "compute_modes",
    "FEModalBasis",
    "PlateModel",
    "assemble_plate",
    "parse_boundary",
    "rigid_body_mode_count",
    "structured_mesh",
    "load_mesh",
    "save_mesh",
]
