"""Plate modal model: FE (Kirchhoff/Argyris, Reissner-Mindlin/Lagrange P4) natural
frequencies and unit-modal-mass mode shapes of the rectangular plate, checked against
closed forms and published tables, with automatic theory/mesh choice and a disk cache.

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
