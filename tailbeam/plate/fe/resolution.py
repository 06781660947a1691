"""'Model only what the scene needs': choose the plate theory and the mesh from the band and
the requested accuracy, and say why.

Theory. Kirchhoff ignores shear deformation and rotary inertia; the SSSS closed forms give
its modelling error at the top of the band, f_K/f_M - 1 at the same wavenumber (about 3 % at
5 kHz and 7 % at 10 kHz for the 10 mm steel plate). 'auto' takes Kirchhoff (cheaper, C1
Argyris) when that error is at most half the accuracy, else Mindlin.

Mesh. The discretisation error of the highest mode in the band follows
    err ~ C (k * dx)^q,   k = bending wavenumber at the top frequency (rad/m),
                          dx = cell size (m) of the structured mesh,
with q the measured convergence order of the element and C fitted to the SSSS closed forms
(benchmarks/bench_modes.py reproduces the fit). We choose the coarsest mesh for which
SAFETY * C (k dx)^q <= the error budget; the safety factor covers clamped/free edges,
which converge a little more slowly than simple supports.
"""

from dataclasses import dataclass

import numpy as np

from tailbeam.errors import InputError, require_positive
from tailbeam.physics.bodies import Plate
from tailbeam.plate.closed_forms import (
    bending_wavenumber,
    kirchhoff_model_error,
    ssss_modes,
)
from tailbeam.plate.fe.mesh import MAX_DIVISIONS, grid_divisions

DEFAULT_FMAX_HZ = 10_000.0
SAFETY = 2.0
MIN_DIVISIONS = 4
# (C, q) per theory, fitted to the SSSS closed forms at the top of the band (10 kHz, 20 kHz)
# on the structured meshes: Argyris errors fall like (k dx)^8, Lagrange-P4 Mindlin like ~7.
ERROR_MODEL = {"kirchhoff": (5.2e-7, 8.0), "mindlin": (1.05e-6, 7.0)}
# count-only requests: top frequency = SSSS-Mindlin frequency of that mode times this margin
# (clamped edges raise frequencies by up to ~1.8x for the first mode, ~1.2x in the band)
COUNT_MARGIN = 1.25


@dataclass(frozen=True)
class Resolution:
    """What compute_modes will build: theory, divisions (None for a user mesh), band and why."""

    theory: str
    divisions: int | None
    top_frequency_hz: float
    predicted_error: float
    kirchhoff_model_error: float
    reason: str


def predicted_error(plate: Plate, theory: str, frequency_hz: float, cell_size_m: float) -> float:
    """Estimated relative frequency error of a mode at ``frequency_hz`` on cells of size dx."""
    c, q = ERROR_MODEL[theory]
    k = float(bending_wavenumber(plate, frequency_hz, theory))
    return SAFETY * c * (k * cell_size_m) ** q


def divisions_for(plate: Plate, theory: str, frequency_hz: float, budget: float) -> int:
    """Coarsest structured mesh (divisions of the longer side) meeting ``budget``."""
    c, q = ERROR_MODEL[theory]
    k = float(bending_wavenumber(plate, frequency_hz, theory))
    cell = (budget / (SAFETY * c)) ** (1.0 / q) / k
    return max(MIN_DIVISIONS, int(np.ceil(max(plate.size_x, plate.size_y) / cell - 1e-9)))


def top_frequency(plate: Plate, fmax_hz, count) -> float:
    """The highest frequency the band reaches (Hz): fmax, or an estimate for a mode count."""
    if fmax_hz is not None:
        return float(fmax_hz)
    f_count = ssss_modes(plate, "mindlin", count=count).frequencies_hz[-1]
    return float(COUNT_MARGIN * f_count)


def resolve(
    plate: Plate, *, theory: str, fmax_hz, count, accuracy: float, user_mesh: bool, divisions
) -> Resolution:
    """Theory and mesh for a request (see module docstring)."""
    accuracy = require_positive("accuracy", accuracy)
    if accuracy >= 0.5:
        raise InputError("accuracy", f"must be a relative error < 0.5, got {accuracy!r}")
    f_top = top_frequency(plate, fmax_hz, count)
    model_err = float(kirchhoff_model_error(plate, f_top))
    if theory == "auto":
        if model_err <= 0.5 * accuracy:
            theory = "kirchhoff"
            budget = accuracy - model_err
            why = (
                f"auto: Kirchhoff's modelling error at {f_top:.0f} Hz is {model_err:.2e} "
                f"<= accuracy/2 = {0.5 * accuracy:.1e}, so the thin theory suffices"
            )
        else:
            theory = "mindlin"
            budget = accuracy
            why = (
                f"auto: Kirchhoff would overestimate modes near {f_top:.0f} Hz by "
                f"{model_err:.2e} > accuracy/2 = {0.5 * accuracy:.1e}: shear and rotary "
                "inertia matter, so Mindlin"
            )
    else:
        budget = accuracy
        why = f"theory {theory!r} requested"
    if user_mesh:
        chosen = None
        why += "; user mesh"
    elif divisions is not None:
        grid_divisions(plate, divisions)  # validates
        chosen = divisions
        why += f"; {divisions} divisions requested"
    else:
        chosen = divisions_for(plate, theory, f_top, budget)
        if chosen > MAX_DIVISIONS:
            raise InputError(
                "fmax_hz" if fmax_hz is not None else "count",
                f"the band up to {f_top:.0f} Hz needs {chosen} mesh divisions per side for "
                f"accuracy {accuracy:g} (the limit is {MAX_DIVISIONS}); ask for a lower band",
            )
        why += (
            f"; {chosen} divisions: predicted discretisation error at {f_top:.0f} Hz "
            f"<= {budget:.1e}"
        )
    err = float("nan")
    if chosen is not None:
        nx, ny = grid_divisions(plate, chosen)
        cell = max(plate.size_x / nx, plate.size_y / ny)
        err = predicted_error(plate, theory, f_top, cell)
    return Resolution(theory, chosen, f_top, err, model_err, why)
