"""What a structure's eigen-solve (``modes.solve_band``) costs, from the assembled model,
before any factorisation.

The solve does three things, and the estimate counts the work of each:

1. the exact count of modes below fmax: a METIS nested-dissection ordering of the matrix
   graph and a SuperLU factorisation of K - (2 pi fmax)^2 M (Sylvester's inertia);
2. the same ordering and factorisation of K - sigma M at the shift;
3. shift-invert Lanczos (ARPACK, ``fe.sparse_solve._eigsh``) for nev = modes + rigid
   modes + ``modes.MARGIN`` eigenpairs in ncv = 1.5 nev + 20 vectors: about
   SOLVES_PER_MODE nev + SOLVES_BASE solves, each a forward and back substitution through the
   factor (its F entries), a product with M, and the orthogonalisation of the new vector
   against the basis (~2 ncv N flops).

The modes: a Weyl-type count of the structure as thin walls (``modes_below``): its
midsurface area A = S/2 and wall thickness h = 2V/S from the mesh's volume V and boundary
area S, and the leading terms of the flexural plate count A k^2 / (4 pi) (k the bending
wavenumber at fmax) and of the two in-plane waves, or of the 3-D count V w^3 / (6 pi^2)
(1/cL^3 + 2/cT^3) of a thick body, whichever is larger. The leading term leaves out the
panels' edges, whose modes start above the band in narrow ribs and walls, so it counts high
at low bands (the example beam: ~1.9x at 2 kHz, ~1.3x at 5 kHz) and never low on the meshes
of the tests.

The factor: nested dissection of a 3-D mesh graph leaves F ~ nnz(K) N^(1/3) entries (its
separators of N^(2/3) vertices are dense in the factor); FILL is that ratio, measured
0.18-0.22 on the test meshes (20-node hexahedra, 2 700-11 400 DOFs) and checked on the
example beam (below). The factorisation's flops ~ F^2 / N (each column's count, F / N on
average, squared).

The rates (s per unit of work) are CPU seconds of one core, measured with
``benchmarks/bench_cost_model.py --solid`` on small meshes (process CPU time, which the
machine's load changes little, where wall time under a load of 13-16 on 2 cores was 5-13x
longer); the example beam at 2 kHz is the check, not the fit: 81 640 DOFs, 121 modes
(estimated 233), 74.8 M factor entries (86 M), 287 solves (495), 81 s CPU (167 s), 2.7 GB
peak (2.3 GB). Memory: the factor (values and row indices, 12 bytes an entry, one factor at
a time), the matrices and their shifted and permuted copies, the Lanczos vectors and the
returned modes.
"""

import math
from dataclasses import dataclass

# ARPACK's shift-invert loop is the flat plate's: its solve rate, orthogonalisation rate and
# solve count (2 nev + 25: 73-210 solves for 24-85 eigenpairs on the test meshes, 287 for
# 123 and 999 for 479 on the example beam, within 10 %)
from tailbeam.plate.fe.cost import ORTH_PER_FLOP, SOLVE_PER_ENTRY, SOLVES_BASE, SOLVES_PER_MODE

FILL = 0.2  # factor entries / (nnz(K) N^(1/3)), nested dissection (module docstring)
ORDER_PER_NNZ = 3.5e-7  # s per nonzero of K: METIS ordering and the graph's copies (3.1-4.6e-7)
FACTOR_PER_FLOP = 1.7e-10  # s per F^2/N: SuperLU's factorisation (measured 1.5-1.9e-10)
MATVEC_PER_NNZ = 3.0e-9  # s per nonzero of M and solve: ARPACK's product with M (*)
FACTOR_BYTES = 12.0  # bytes per factor entry: a double and an int32 row index
MATRIX_COPIES = 4.0  # K, M, K - sigma M and its permuted CSC copy held at once
# (*) the rest of a Lanczos step, 7 ms on 11 385 DOFs and 147 vectors, with the
# orthogonalisation at the flat plate's rate
BASE_MEMORY = 2.1e8  # bytes: interpreter, numpy/scipy/skfem (the smallest mesh's peak)


@dataclass(frozen=True)
class StructureSolveCost:
    """Estimated size and work of a structure's eigen-solve: DOFs, modes (Weyl-type count),
    factor entries, shift-invert solves, peak memory (bytes) and CPU time (s)."""

    n_dofs: int
    n_modes: int
    factor_entries: float
    solves: int
    memory_bytes: float
    time_s: float
    factorise_s: float = 0.0  # one ordering and factorisation of K (the static compliance)

    def describe(self) -> str:
        """e.g. '~233 modes on 81 640 DOFs, ~75 M factor entries, ~490 solves'."""
        dofs = f"{self.n_dofs:,}".replace(",", " ")
        return (f"~{self.n_modes} modes on {dofs} DOFs, ~{self.factor_entries / 1e6:.0f} M "
                f"factor entries, ~{self.solves} solves")  # fmt: skip


def mesh_volume_area(mesh) -> tuple:
    """(volume m^3, boundary area m^2) of a skfem MeshTet or MeshHex."""
    from skfem import Basis, ElementHex0, ElementTetP0, FacetBasis, Functional, MeshHex

    element = ElementHex0() if isinstance(mesh, MeshHex) else ElementTetP0()
    one = Functional(lambda w: 1.0 + 0.0 * w.x[0])
    return float(one.assemble(Basis(mesh, element))), float(one.assemble(FacetBasis(mesh, element)))


def modes_below(volume: float, area: float, material, fmax_hz: float) -> int:
    """Weyl-type count of a structure's elastic modes below ``fmax_hz`` (Hz) from its volume
    (m^3), boundary area (m^2) and material: the larger of the thin-wall count (flexural
    and in-plane waves of walls of midsurface area/2, thickness 2 volume/area) and the 3-D
    count (module docstring)."""
    e, nu, rho = material.youngs_modulus, material.poisson_ratio, material.density
    omega = 2.0 * math.pi * fmax_hz
    h, a = 2.0 * volume / area, 0.5 * area
    bending = 12.0 * rho * (1.0 - nu * nu) / e  # rho h / D times h^2, s^2/m^2
    flexural = a * omega * math.sqrt(bending) / h / (4.0 * math.pi)
    c_plate = math.sqrt(e / (rho * (1.0 - nu * nu)))
    c_shear = math.sqrt(e / (2.0 * rho * (1.0 + nu)))
    c_long = math.sqrt(e * (1.0 - nu) / (rho * (1.0 + nu) * (1.0 - 2.0 * nu)))
    in_plane = a * omega**2 / (4.0 * math.pi) * (c_plate**-2 + c_shear**-2)
    solid = volume * omega**3 / (6.0 * math.pi**2) * (c_long**-3 + 2.0 * c_shear**-3)
    return int(math.ceil(max(flexural + in_plane, solid)))


def factor_entries(n_dofs: int, nnz: int) -> float:
    """Estimated entries of the nested-dissection factor (L and U) of an ``n_dofs`` matrix
    with ``nnz`` nonzeros from a 3-D mesh."""
    return FILL * nnz * n_dofs ** (1.0 / 3.0)


def solve_cost(n_dofs: int, nnz: int, n_modes: int, extra: int = 0) -> StructureSolveCost:
    """Memory (bytes) and CPU time (s) of solving ``n_modes`` modes (plus ``extra``: rigid
    modes and the margin) of a structure of ``n_dofs`` DOFs whose K has ``nnz`` nonzeros."""
    f = factor_entries(n_dofs, nnz)
    nev = n_modes + extra
    ncv = min(n_dofs, int(1.5 * nev) + 20)
    solves = int(SOLVES_PER_MODE * nev + SOLVES_BASE)
    factorise = ORDER_PER_NNZ * nnz + FACTOR_PER_FLOP * f * f / n_dofs
    per_solve = SOLVE_PER_ENTRY * f + MATVEC_PER_NNZ * nnz + ORTH_PER_FLOP * 2.0 * ncv * n_dofs
    time_s = 2.0 * factorise + solves * per_solve
    vectors = 8.0 * n_dofs * (ncv + 2 * nev)  # Lanczos basis, returned modes and a copy
    memory = BASE_MEMORY + FACTOR_BYTES * (f + MATRIX_COPIES * nnz) + vectors
    return StructureSolveCost(int(n_dofs), int(n_modes), f, solves, memory, time_s, factorise)


def structure_cost(model, fmax_hz: float) -> StructureSolveCost:
    """The estimated cost of ``modes.structure_modes(model, fmax_hz=...)`` (a
    StructureModel)."""
    from tailbeam.plate.solid.cached import stiffness_nnz
    from tailbeam.plate.solid.modes import MARGIN

    volume, area = mesh_volume_area(model.vmesh.mesh)
    n_modes = modes_below(volume, area, model.plate.material, fmax_hz)
    nnz = stiffness_nnz(model)  # from the cache when K was assembled before
    return solve_cost(model.n_dofs, nnz, n_modes, model.rigid_modes + MARGIN)
