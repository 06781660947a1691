"""Kirchhoff (thin) plate: conforming C1 Argyris triangles (quintic, 21 DOFs per element).

Stiffness  K = int D [(1 - nu) w,ij v,ij + nu w,ii v,jj] dA  (bending energy, D = E h^3/12(1-nu^2))
Mass       M = int rho h w v dA                                (no rotary inertia)

The Argyris element is C1, so this is a conforming discretisation of the biharmonic problem;
its eigenvalue error falls like (mesh size)^8 (twice the H2 rate p - 1 = 4 of quintics).
"""

import numpy as np
from skfem import Basis, BilinearForm, ElementTriArgyris, MeshTri
from skfem.helpers import dd, ddot, trace

from tailbeam.physics.bodies import Plate
from tailbeam.plate.fe.boundary import EDGES, kirchhoff_fixed_names

ELEMENT_NAME = "Argyris (quintic C1 triangle)"
QUADRATURE_ORDER = 10  # integrates the quintic mass matrix exactly


def _bending_form(bending_stiffness: float, poisson_ratio: float) -> BilinearForm:
    d, nu = bending_stiffness, poisson_ratio

    @BilinearForm
    def bending(u, v, w):
        hu, hv = dd(u), dd(v)
        return d * ((1.0 - nu) * ddot(hu, hv) + nu * trace(hu) * trace(hv))

    return bending


def assemble_kirchhoff(plate: Plate, boundary: str, mesh: MeshTri):
    """Full (unconstrained) K, M, the Argyris basis and the fixed DOF indices.

    Returns (K, M, basis, fixed): K, M scipy CSR (N x N); basis an skfem Basis whose DOF
    vector is the full vector (u is the deflection, m); fixed a sorted int array.
    """
    # a fresh element per mesh: ElementGlobal caches its per-mesh inverse Vandermonde matrices
    basis = Basis(mesh, ElementTriArgyris(), intorder=QUADRATURE_ORDER)
    stiffness = _bending_form(plate.bending_stiffness, plate.material.poisson_ratio)
    rho_h = plate.mass_per_area

    @BilinearForm
    def mass(u, v, w):
        return rho_h * u * v

    K = stiffness.assemble(basis).tocsr()
    M = mass.assemble(basis).tocsr()
    fixed = [np.zeros(0, dtype=np.int64)]
    for edge, condition in zip(EDGES, boundary, strict=True):
        names = kirchhoff_fixed_names(edge, condition)
        if names:
            fixed.append(np.asarray(basis.get_dofs(edge).all(names), dtype=np.int64))
    return K, M, basis, np.unique(np.concatenate(fixed))
