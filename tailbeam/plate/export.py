"""Writing a modal basis for people: frequencies.csv, mode shapes as VTU (ParaView) and PNG.

I/O only; the physics lives in the other modules.
"""

import csv
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import meshio  # noqa: E402
import numpy as np  # noqa: E402
from skfem import MeshTri  # noqa: E402

from tailbeam.modal import ModalBasis  # noqa: E402

VTU_REFINE = 2  # each triangle split into 4^2 for a smooth picture of the quintic shapes
PNG_MODES = 12
PNG_GRID = 121


def write_frequencies_csv(
    path, freqs_hz, theory: str, reference_hz=None, reference_name: str = ""
) -> Path:
    """CSV: mode, frequency_hz, theory, reference_hz, reference, rel_error (blank if none)."""
    path = Path(path)
    with path.open("w", newline="") as fh:
        out = csv.writer(fh)
        out.writerow(["mode", "frequency_hz", "theory", "reference_hz", "reference", "rel_error"])
        for i, f in enumerate(freqs_hz):
            ref = None
            if reference_hz is not None and i < len(reference_hz):
                ref = float(reference_hz[i])
            out.writerow(
                [
                    i + 1,
                    f"{f:.10g}",
                    theory,
                    "" if ref is None else f"{ref:.10g}",
                    reference_name if ref is not None else "",
                    "" if ref is None else f"{(f - ref) / ref:.3e}",
                ]
            )
    return path


def write_vtu(
    path, basis: ModalBasis, mesh: MeshTri | None = None, max_modes: int | None = None
) -> Path:
    """Mode shapes on a refined copy of the FE mesh (default: the basis's own mesh): one
    point field per mode, 'mode_001_<f>Hz' (deflection, 1/sqrt(kg)); in ParaView use
    'Warp By Scalar' to see the shape."""
    mesh = mesh if mesh is not None else basis.mesh
    fine = mesh.refined(VTU_REFINE) if VTU_REFINE else mesh
    n = basis.n_modes if max_modes is None else min(max_modes, basis.n_modes)
    phi = basis.deflection(fine.p.T)[:, :n]
    width = max(3, len(str(n)))
    data = {f"mode_{i + 1:0{width}d}_{basis.frequencies_hz[i]:.1f}Hz": phi[:, i] for i in range(n)}
    points = np.column_stack([fine.p.T, np.zeros(fine.p.shape[1])])
    meshio.write(Path(path), meshio.Mesh(points, [("triangle", fine.t.T)], point_data=data))
    return Path(path)


def write_png(path, basis: ModalBasis, n_modes: int = PNG_MODES) -> Path:
    """A grid of the first modes' deflection (colour), with frequencies in the titles."""
    plate = basis.plate
    n = min(n_modes, basis.n_modes)
    a, b = plate.size_x, plate.size_y
    x = np.linspace(-0.5 * a, 0.5 * a, PNG_GRID)
    y = np.linspace(-0.5 * b, 0.5 * b, PNG_GRID)
    xx, yy = np.meshgrid(x, y)
    phi = basis.deflection(np.column_stack([xx.ravel(), yy.ravel()]))[:, :n]
    cols = min(4, n)
    rows = int(np.ceil(n / cols))
    fig, axes = plt.subplots(rows, cols, figsize=(3.0 * cols, 3.0 * rows), squeeze=False)
    for i, ax in enumerate(axes.ravel()):
        ax.set_axis_off()
        if i >= n:
            continue
        z = phi[:, i].reshape(xx.shape)
        lim = np.abs(z).max() or 1.0
        ax.pcolormesh(xx, yy, z, cmap="RdBu_r", vmin=-lim, vmax=lim, shading="auto")
        # nodal lines, inside only (the supported edges are zero everywhere)
        ax.contour(
            xx[1:-1, 1:-1], yy[1:-1, 1:-1], z[1:-1, 1:-1], levels=[0.0], colors="k", linewidths=0.6
        )
        ax.set_aspect("equal")
        ax.set_title(f"mode {i + 1}: {basis.frequencies_hz[i]:.1f} Hz", fontsize=9)
    fig.suptitle(
        f"{basis.boundary} plate, {basis.theory} ({basis.info.get('element', '')})", fontsize=10
    )
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)
