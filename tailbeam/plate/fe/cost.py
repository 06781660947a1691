"""The work of a modal solve, estimated before anything is assembled: DOFs, modes, memory, time.

DOFs are counted exactly from the mesh (nodes of the element), before any assembly.
Modes: the Weyl-type count of tailbeam.plate.fe.modes (slightly high). The time counts the
work of ``modes._solve_band`` (CPU seconds of one core, one BLAS thread):

- assembling the FE model: ASSEMBLY_PER_DOF per DOF;
- two factorisations (the shift's, and Sylvester's count at fmax) with SuperLU's minimum
  degree, whose factor on these 2-D meshes has F = FILL x N^(4/3) entries (measured 7.10 x
  on 6 815 DOFs, 7.11 x on 13 735, 6.81 x on 29 799), each FACTOR_PER_FLOP x F^2 / N;
- shift-invert Lanczos for nev modes in ncv = 1.5 nev + 20 vectors: 2 nev + 25 solves
  (measured 137, 249, 501 for 52, 112, 253 modes), each a forward and
  back substitution (SOLVE_PER_ENTRY x F), the products with M (STEP_PER_DOF x N) and the
  orthogonalisation of the new vector against ~(nev + ncv) / 2 others (2 flops each per DOF,
  ORTH_PER_FLOP).

The rates were measured on the default plate's solves at 5, 10 and 20 kHz in process CPU
time (``benchmarks/bench_cost_model.py``'s notes in docs/band-and-cost.md), which the
machine's load changes little; the wall time is longer by about the load average over the
cores. Memory ~ N m (the Lanczos vectors, the returned shapes and their copies:
MEMORY_WORDS_PER_DOF_MODE doubles per DOF per mode, which also covers the factorisation's
fill) on top of the interpreter's BASE_MEMORY. The limits decide whether to start.
"""

from dataclasses import dataclass

from tailbeam.errors import InputError

FILL = 7.0  # factor entries / N^(4/3), SuperLU minimum degree on the plate's meshes
ASSEMBLY_PER_DOF = 6e-5  # s per DOF: the FE model's assembly (measured 5-6e-5)
FACTOR_PER_FLOP = 6e-10  # s per F^2/N of a factorisation (measured 4-7e-10)
SOLVE_PER_ENTRY = 2.0e-9  # s per factor entry and solve (measured 1.8-2.2e-9)
STEP_PER_DOF = 1e-7  # s per DOF and solve: ARPACK's products with M
ORTH_PER_FLOP = 1e-9  # s per flop of orthogonalisation (memory-bound dgemv)
SOLVES_PER_MODE, SOLVES_BASE = 2.0, 25.0  # ARPACK's solves: 2 nev + 25
MEMORY_WORDS_PER_DOF_MODE = 6.0  # doubles per DOF per mode
BASE_MEMORY = 1.5e8  # bytes: interpreter, numpy/scipy/skfem, assembly
MEMORY_LIMIT = 3.0e9  # bytes: refuse a band whose solve needs more (23 GB shared by ~5 jobs)
TIME_LIMIT = 600.0  # s: refuse a band whose eigen-solve would take longer


@dataclass(frozen=True)
class SolveCost:
    """Estimated size and work of one eigen-solve."""

    n_dofs: int
    n_modes: int
    memory_bytes: float
    time_s: float

    def describe(self) -> str:
        """e.g. '~253 modes on 30 603 DOFs, ~0.8 GB, ~20 s'."""
        dofs = f"{self.n_dofs:,}".replace(",", " ")
        return (
            f"~{self.n_modes} modes on {dofs} DOFs, "
            f"~{self.memory_bytes / 1e9:.1f} GB, ~{self.time_s:.0f} s"
        )

    def as_dict(self) -> dict:
        return {
            "n_dofs": self.n_dofs,
            "n_modes": self.n_modes,
            "memory_bytes": self.memory_bytes,
            "time_s": self.time_s,
        }


def mesh_dofs(mesh, theory: str, mindlin_degree: int = 4) -> int:
    """DOFs (before edge conditions) of ``theory`` on a triangle mesh (skfem MeshTri)."""
    nv, ne, nt = mesh.p.shape[1], mesh.facets.shape[1], mesh.t.shape[1]
    if theory == "kirchhoff":  # Argyris: 6 per vertex + 1 per edge
        return 6 * nv + ne
    interior = {3: (2, 1), 4: (3, 3)}[mindlin_degree]  # Lagrange P_p nodes per edge, triangle
    return 3 * (nv + interior[0] * ne + interior[1] * nt)  # w, beta_x, beta_y


def solve_cost(n_dofs: int, n_modes: int) -> SolveCost:
    """Memory (bytes) and time (s) of finding ``n_modes`` modes of an ``n_dofs`` model."""
    memory = BASE_MEMORY + 8.0 * MEMORY_WORDS_PER_DOF_MODE * n_dofs * n_modes
    return SolveCost(int(n_dofs), int(n_modes), memory, solve_time(n_dofs, n_modes))


def solve_time(n_dofs: int, n_modes: int) -> float:
    """CPU time (s) of assembling an ``n_dofs`` plate model and solving ``n_modes`` modes
    (module docstring)."""
    n = float(n_dofs)
    f = FILL * n ** (4.0 / 3.0)
    ncv = min(n, 1.5 * n_modes + 20)
    solves = SOLVES_PER_MODE * n_modes + SOLVES_BASE
    per_solve = SOLVE_PER_ENTRY * f + STEP_PER_DOF * n + ORTH_PER_FLOP * (n_modes + ncv) * n
    return ASSEMBLY_PER_DOF * n + 2.0 * FACTOR_PER_FLOP * f * f / n + solves * per_solve


def check_cost(cost: SolveCost, field: str, what: str, advice: str) -> None:
    """InputError naming ``field`` when ``cost`` exceeds MEMORY_LIMIT or TIME_LIMIT.

    what: the request in words, e.g. 'the band up to 72000 Hz'; advice: what to do."""
    if cost.memory_bytes > MEMORY_LIMIT or cost.time_s > TIME_LIMIT:
        raise InputError(
            field,
            f"{what}: {cost.describe()} (estimated), above the limits "
            f"{MEMORY_LIMIT / 1e9:.0f} GB / {TIME_LIMIT:.0f} s; {advice}",
        )
