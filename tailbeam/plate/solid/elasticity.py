"""Linear elasticity of a solid: stiffness and mass matrices on quadratic elements.

Elements (scikit-fem): 27-node triquadratic hexahedra (``ElementHex2``) on hexahedral meshes,
10-node quadratic tetrahedra (``ElementTetP2``) on tetrahedral ones, three displacement
components each. Quadratic fields represent a plate's bending (u linear, w quadratic through
the thickness, the Poisson thickening included) exactly in one element through the
thickness, so thin steel plates need no reduced integration; the convergence study is in
docs/structures.md (benchmarks/bench_structure_modes.py).
"""

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp
from skfem import Basis, ElementHexS2, ElementTetP2, ElementVector
from skfem.models.elasticity import lame_parameters

from tailbeam.physics.materials import Material

ELEMENTS = {"tetra": ElementTetP2, "hexahedron": ElementHexS2}
ELEMENT_NAMES = {
    "tetra": "quadratic tetrahedra (10 nodes, P2)",
    "hexahedron": "serendipity quadratic hexahedra (20 nodes)",
}
INTEGRATION_ORDER = 4  # exact for the Q2/P2 mass and stiffness on straight-sided cells


@dataclass(frozen=True, eq=False)
class Elasticity:
    """The assembled solid: full (unconstrained) matrices on the vector basis' DOFs.

    stiffness : (N, N) CSR, N/m; mass : (N, N) CSR, kg; basis : skfem vector Basis
    (``basis.split_indices()`` gives the DOFs of each displacement component).
    """

    basis: Basis
    stiffness: sp.csr_matrix
    mass: sp.csr_matrix
    element: str


def vector_basis(mesh, kind: str) -> Basis:
    """The displacement basis (three components) of the element chosen for ``kind``."""
    return Basis(mesh, ElementVector(ELEMENTS[kind]()), intorder=INTEGRATION_ORDER)


def dof_basis(mesh, kind: str) -> Basis:
    """The same displacement basis without quadrature points: its DOF numbering, DOF
    locations, element and mapping are those of ``vector_basis`` (they do not depend on the
    quadrature), without the basis values and gradients at every cell's quadrature points
    that only the assembly needs (seconds and hundreds of MB on a beam's mesh)."""
    none = (np.zeros((mesh.dim(), 0)), np.zeros(0))
    return Basis(mesh, ElementVector(ELEMENTS[kind]()), quadrature=none)


def assemble_elasticity(mesh, kind: str, material: Material) -> Elasticity:
    """Stiffness and mass of an isotropic linear elastic solid (``material``: E Pa, nu, rho
    kg/m^3) on ``mesh`` (``kind`` 'tetra' or 'hexahedron').

    The element matrices are batched products over the cells (``_element_stiffness``) of the
    scalar element's gradients from scikit-fem: the same integrals as
    ``skfem.models.elasticity.linear_elasticity`` (checked against it in the tests), whose
    pair-by-pair assembly takes minutes on a beam's mesh.
    """
    return assemble_on(vector_basis(mesh, kind), material, ELEMENT_NAMES[kind])


def assemble_on(basis: Basis, material: Material, element: str) -> Elasticity:
    """``assemble_elasticity`` on a given vector ``basis`` (its quadrature integrates)."""
    mesh = basis.mesh
    scalar = basis.split_bases()[0]
    lam, mu = lame_parameters(material.youngs_modulus, material.poisson_ratio)
    grads = np.array([scalar.basis[a][0].grad for a in range(scalar.Nbfun)])  # (nb, 3, e, q)
    values = np.array([np.asarray(scalar.basis[a][0]) for a in range(scalar.Nbfun)])  # (nb, e, q)
    dofs = np.array([idx[scalar.element_dofs] for idx in basis.split_indices()])  # (3, nb, e)
    k_rows, k_vals = [], []
    for cells in np.array_split(np.arange(mesh.t.shape[1]), max(1, mesh.t.shape[1] // CHUNK)):
        k_vals.append(_element_stiffness(grads[:, :, cells], scalar.dx[cells], lam, mu))
        k_rows.append(dofs[:, :, cells].transpose(2, 1, 0).reshape(len(cells), -1))
    stiffness = _assemble(np.concatenate(k_vals), np.concatenate(k_rows), basis.N)
    m_scalar = material.density * np.einsum("aeq,beq,eq->eab", values, values, scalar.dx)
    mass = sum(
        _assemble(m_scalar, dofs[c].T, basis.N) for c in range(3)
    )  # the same scalar mass on each component
    return Elasticity(basis, stiffness, mass.tocsr(), element)


CHUNK = 500  # cells per batch of element matrices (~50 MB each for Q2 hexahedra)


def _element_stiffness(grads, dx, lam, mu) -> np.ndarray:
    """(e, 3 nb, 3 nb) element stiffness, local DOFs ordered (function a, component i):
    K[ai, bj] = int lam d_i N_a d_j N_b + mu (delta_ij grad N_a . grad N_b + d_j N_a d_i N_b)."""
    nb, _, e, q = grads.shape
    g = grads.transpose(2, 3, 0, 1)  # (e, q, nb, 3)
    gw = g * dx[:, :, None, None]
    # lam and the second mu term: sum_q (g_ai gw_bj), arranged (a i, b j) or (a j, b i)
    outer = np.einsum("eqai,eqbj->eaibj", g, gw, optimize=True)
    lap = np.einsum("eaibi->eab", outer)  # grad N_a . grad N_b (weighted)
    k = lam * outer + mu * outer.transpose(0, 1, 4, 3, 2)  # swap i and j
    k = k + mu * np.einsum("eab,ij->eaibj", lap, np.eye(3))
    return k.reshape(e, 3 * nb, 3 * nb)


def _assemble(blocks, dofs, n) -> sp.csr_matrix:
    """Sum element matrices (e, d, d) on their global DOFs (e, d) into an (n, n) matrix."""
    d = dofs.shape[1]
    rows = np.repeat(dofs, d, axis=1).ravel()
    cols = np.tile(dofs, (1, d)).ravel()
    return sp.coo_matrix((blocks.ravel(), (rows, cols)), shape=(n, n)).tocsr()


def rigid_body_modes(basis: Basis, center=None) -> np.ndarray:
    """(N, 6) rigid motions on the DOFs: translations x, y, z (unit m) and rotations about x,
    y, z through ``center`` (default the DOF locations' centroid), in rad times the
    structure's size so all six have comparable amplitudes."""
    locs = basis.doflocs  # (3, N): the point each DOF's value belongs to
    comp = components(basis)
    center = locs.mean(axis=1) if center is None else np.asarray(center, dtype=float)
    r = locs - center[:, None]
    scale = float(np.max(np.linalg.norm(r, axis=0))) or 1.0
    out = np.zeros((basis.N, 6))
    for c in range(3):
        out[comp == c, c] = 1.0
    for a in range(3):
        axis = np.zeros(3)
        axis[a] = 1.0
        motion = np.cross(axis, r.T).T / scale  # (3, N): velocity of each point
        out[:, 3 + a] = motion[comp, np.arange(basis.N)]
    return out


def components(basis: Basis) -> np.ndarray:
    """(N,) the displacement component (0 x, 1 y, 2 z) of each DOF."""
    comp = np.empty(basis.N, dtype=np.int64)
    for c, idx in enumerate(basis.split_indices()):
        comp[idx] = c
    return comp
