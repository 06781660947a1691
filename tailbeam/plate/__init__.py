"""The plate's modal model: the basis every solver takes (``basis``: natural frequencies,
unit-modal-mass mode shapes, modal damping), closed forms and published tables (``closed_forms``),
the finite-element model (``fe``: Kirchhoff/Argyris, Reissner-Mindlin/Lagrange P4, with
automatic theory and mesh choice), the disk cache (``cache``), the residual compliance of the
truncated modes (``compliance``) and the tails that stand in for them at a contact
(``ritz_tail``, ``contact_tail``).

    from tailbeam.plate import compute_modes, PlateModel, assemble_plate

These names load with the finite-element model (scikit-fem) on first use, so a submodule that
needs neither (``tailbeam.plate.export``) imports without it.
"""

from typing import TYPE_CHECKING

if TYPE_CHECKING:  # the same names, for type checkers and editors
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


def __getattr__(name: str):
    """A name of ``__all__``, imported from ``tailbeam.plate.fe`` on first use (PEP 562)."""
    if name not in __all__:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    from tailbeam.plate.fe import boundary, mesh, model, modes

    for module in (boundary, mesh, model, modes):
        if name in vars(module):
            globals()[name] = value = vars(module)[name]
            return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list:
    return sorted(set(globals()) | set(__all__))
