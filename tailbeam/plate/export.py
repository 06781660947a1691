"""Writing a modal basis for people: frequencies.csv, mode shapes as VTU (ParaView) and PNG.

I/O only; the physics lives in the other modules. meshio and matplotlib are imported by the
writers that need them, so writing frequencies.csv from a cached basis stays fast.
"""

import csv
import textwrap
from pathlib import Path

import numpy as np

from tailbeam.plate.basis import ModalBasis
from tailbeam.plate.fe.boundary import CONDITIONS, EDGES
from tailbeam.plate.mode_labels import label_modes

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


GRID_CELLS = 32  # cells per side of the surface of a basis without a mesh


def surface(basis: ModalBasis, mesh=None) -> tuple:
    """The impact face (z = 0, plate frame) as written for ParaView: (points (p, 3) m,
    triangles (t, 3)) of a refined copy (VTU_REFINE) of ``mesh`` (default: the basis's own
    FE mesh), or of a GRID_CELLS x GRID_CELLS grid of the plate for a basis without one."""
    mesh = mesh if mesh is not None else getattr(basis, "mesh", None)
    if mesh is None:
        return grid_surface(basis.plate.size_x, basis.plate.size_y, GRID_CELLS)
    fine = mesh.refined(VTU_REFINE) if VTU_REFINE else mesh
    points = np.column_stack([fine.p.T, np.zeros(fine.p.shape[1])])
    return points, np.ascontiguousarray(fine.t.T)


def grid_surface(a: float, b: float, cells: int) -> tuple:
    """(points (p, 3), triangles (t, 3)) of an ``a`` x ``b`` m rectangle centred on the
    origin at z = 0, ``cells`` x ``cells`` squares each split in two triangles."""
    x = np.linspace(-0.5 * a, 0.5 * a, cells + 1)
    y = np.linspace(-0.5 * b, 0.5 * b, cells + 1)
    xx, yy = np.meshgrid(x, y, indexing="ij")
    points = np.column_stack([xx.ravel(), yy.ravel(), np.zeros(xx.size)])
    i, j = np.meshgrid(np.arange(cells), np.arange(cells), indexing="ij")
    n0 = (i * (cells + 1) + j).ravel()
    n1, n2, n3 = n0 + cells + 1, n0 + cells + 2, n0 + 1
    tris = np.concatenate([np.column_stack([n0, n1, n2]), np.column_stack([n0, n2, n3])])
    return points, tris


def write_vtu(path, basis: ModalBasis, mesh=None, max_modes: int | None = None) -> Path:
    """Mode shapes on the impact face (``surface``: a refined copy of the FE mesh, default
    the basis's own): one point field per mode, 'mode_001_<f>Hz' (deflection normal to the
    face, + up, 1/sqrt(kg)); in ParaView use 'Warp By Scalar' to see the shape. The points
    and cells are those of the plate in a ``simulate --vtk`` series (tailbeam.io.paraview)."""
    import meshio

    points, triangles = surface(basis, mesh)
    n = basis.n_modes if max_modes is None else min(max_modes, basis.n_modes)
    phi = basis.deflection(points[:, :2])[:, :n]
    width = max(3, len(str(n)))
    data = {f"mode_{i + 1:0{width}d}_{basis.frequencies_hz[i]:.1f}Hz": phi[:, i] for i in range(n)}
    meshio.write(Path(path), meshio.Mesh(points, [("triangle", triangles)], point_data=data))
    return Path(path)


EDGE_STYLES = {  # boundary letter -> how the edge is drawn
    "C": {"color": "black", "lw": 3.0, "ls": "-"},
    "S": {"color": "black", "lw": 1.5, "ls": "--"},
    "F": {"color": "0.45", "lw": 1.2, "ls": ":"},
}


def _edge_segments(a: float, b: float) -> list:
    """(xs, ys) of the edges left, bottom, right, top (the boundary code's order)."""
    ha, hb = 0.5 * a, 0.5 * b
    return [
        ((-ha, -ha), (-hb, hb)),
        ((-ha, ha), (-hb, -hb)),
        ((ha, ha), (-hb, hb)),
        ((-ha, ha), (hb, hb)),
    ]


def _draw_edges(ax, boundary: str, a: float, b: float) -> None:
    """Each edge of the plate in its condition's style (EDGE_STYLES)."""
    for letter, (xs, ys) in zip(boundary, _edge_segments(a, b), strict=True):
        ax.plot(xs, ys, clip_on=False, **EDGE_STYLES[letter])


def write_png(path, basis: ModalBasis, n_modes: int = PNG_MODES) -> Path:
    """Write build_modes_figure(basis, n_modes) to ``path`` (PNG); returns the path."""
    build_modes_figure(basis, n_modes).savefig(path, dpi=110)
    return Path(path)


def build_modes_figure(basis: ModalBasis, n_modes: int = PNG_MODES):
    """A grid of the first modes' deflection (colour, nodal lines in black) with frequency and
    (m, n) label in the titles (tailbeam.plate.mode_labels) and the edge conditions drawn on
    every panel (solid: clamped, dashed: simply supported, dotted: free)."""
    from matplotlib.figure import Figure

    plate = basis.plate
    n = min(n_modes, basis.n_modes)
    a, b = plate.size_x, plate.size_y
    x = np.linspace(-0.5 * a, 0.5 * a, PNG_GRID)
    y = np.linspace(-0.5 * b, 0.5 * b, PNG_GRID)
    xx, yy = np.meshgrid(x, y)
    phi = basis.deflection(np.column_stack([xx.ravel(), yy.ravel()]))[:, :n]
    shapes = [phi[:, i].reshape(xx.shape) for i in range(n)]
    labels = label_modes(basis.boundary, shapes, x, y, a, b)
    cols = min(4, n)
    rows = int(np.ceil(n / cols))
    width = max(3.0 * cols, 6.0)
    fig = Figure(figsize=(width, 3.0 * rows + 1.2), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False)
    for i, ax in enumerate(axes.ravel()):
        ax.set_axis_off()
        if i >= n:
            continue
        z = shapes[i]
        lim = np.abs(z).max() or 1.0
        ax.pcolormesh(xx, yy, z, cmap="RdBu_r", vmin=-lim, vmax=lim, shading="auto")
        # nodal lines, inside only (supported or clamped edges are zero everywhere)
        ax.contour(
            xx[1:-1, 1:-1], yy[1:-1, 1:-1], z[1:-1, 1:-1], levels=[0.0], colors="k", linewidths=0.6
        )
        _draw_edges(ax, basis.boundary, a, b)
        ax.set_aspect("equal")
        ax.set_title(
            f"mode {i + 1}: {basis.frequencies_hz[i]:.1f} Hz\n{labels[i].text()}", fontsize=8
        )
    fig.suptitle(_heading(basis, width, n), fontsize=9)
    fig.legend(handles=_legend_handles(), loc="outside lower center", ncols=4, fontsize=8)
    return fig


def _heading(basis: ModalBasis, width_in: float, shown: int) -> str:
    """Title lines: which modes are shown (the first ``shown`` of the basis), plate, theory,
    edge conditions, how to read a panel; wrapped to fit a figure ``width_in`` inches wide
    (at 9 pt, about 14 characters per inch)."""
    edges = ", ".join(
        f"{edge} {CONDITIONS[c]}" for edge, c in zip(EDGES, basis.boundary, strict=True)
    )
    plate = basis.plate
    meaning = (
        "(m, n): the SSSS sine sin(m pi x/a) sin(n pi y/b) with the largest share of the shape"
        if basis.boundary == "SSSS"
        else "nodal (m, n): 1 + nodal lines crossed along x, along y (a half-wave count, "
        "not a closed-form index)"
    )
    total = basis.n_modes
    which = f"first {shown} of {total} modes" if shown < total else f"all {total} modes"
    lines = [
        f"{which}: {basis.boundary} plate {plate.size_x:g} x {plate.size_y:g} x "
        f"{plate.thickness:g} m, "
        f"{basis.theory} ({basis.info.get('element', '')})",
        f"edges: {edges}",
        "x to the right, y up; colour: deflection (red +, blue -), black: nodal lines",
        meaning,
    ]
    return "\n".join(textwrap.fill(line, int(14 * width_in)) for line in lines)


def _legend_handles() -> list:
    from matplotlib.lines import Line2D

    return [Line2D([], [], label=CONDITIONS[c], **style) for c, style in EDGE_STYLES.items()]
