"""The work of a modal solve, estimated before anything is assembled: DOFs, modes, memory, time.

DOFs are counted exactly from the mesh (nodes of the element), before any assembly.
Modes: the Weyl-type count of tailbeam.plate.fe.modes (slightly high). Memory and time are
fitted to measured eigen-solves of the default plate on this project's 2-core machine, one
BLAS thread, under load (benchmarks/bench_band.py):

    10 kHz:  13 735 DOFs, 112 modes,  1.6 s,  0.19 GB peak
    20 kHz:  29 799 DOFs, 253 modes, 12.4 s
    30 kHz:  45 879 DOFs, 410 modes, 76.5 s,  0.95 GB peak

Shift-invert Lanczos keeps ~1.5 m + 20 vectors of N doubles and orthogonalises each new one
against them, so time ~ N m^2 (TIME_COEFF s per DOF per mode^2) and memory ~ N m (the Lanczos
vectors, the returned shapes and their copies: MEMORY_WORDS_PER_DOF_MODE doubles per DOF per
mode, which also covers the factorisation's fill) on top of the interpreter's BASE_MEMORY.
Both estimates sit at or above every measured point; they decide whether to start, not how
long a progress bar is.
"""

from dataclasses import dataclass

from tailbeam.errors import InputError

TIME_COEFF = 1.2e-8  # s / (DOF mode^2), one BLAS thread (measured 0.65-1.0e-8)
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
    return SolveCost(int(n_dofs), int(n_modes), memory, TIME_COEFF * n_dofs * n_modes**2)


def check_cost(cost: SolveCost, field: str, what: str, advice: str) -> None:
    """InputError naming ``field`` when ``cost`` exceeds MEMORY_LIMIT or TIME_LIMIT.

    what: the request in words, e.g. 'the band up to 72000 Hz'; advice: what to do."""
    if cost.memory_bytes > MEMORY_LIMIT or cost.time_s > TIME_LIMIT:
        raise InputError(
            field,
            f"{what}: {cost.describe()} (estimated), above the limits "
            f"{MEMORY_LIMIT / 1e9:.0f} GB / {TIME_LIMIT:.0f} s; {advice}",
        )
