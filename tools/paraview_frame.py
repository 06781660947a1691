"""Draw one frame of a `tailbeam simulate --vtk` series as a PNG, without ParaView.

    python tools/paraview_frame.py OUT/vtk --time 0.5 --out frame.png

Reads the series with ElementTree (.pvd) and meshio (.vtu) and draws two views with
matplotlib: the side (world x-z, gravity down, particles as discs of their radius) and the
face seen along its normal (the plate frame's x-y, coloured by the plate's deflection, the
particles as discs). The frame shown is the last one at or before --time.
"""

import argparse
import json
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

LABEL_COLOURS = {0: "0.15", 1: "tab:orange"}  # coal, gangue (tailbeam.io.paraview.LABEL_CODES)
TOUCH_GAP = 1e-3  # m: a particle this close to the face is drawn filled in the face view


def read_collection(path: Path) -> tuple:
    """(times (F,), files [F]) of a .pvd collection."""
    sets = ET.parse(path).getroot().find("Collection").findall("DataSet")
    return np.array([float(d.get("timestep")) for d in sets]), [d.get("file") for d in sets]


def read_frame(folder: Path, name: str):
    """(points (p, 3), point fields) of one VTU file; no points for an empty frame."""
    import meshio

    piece = ET.parse(folder / name).getroot().find("UnstructuredGrid/Piece")
    if int(piece.get("NumberOfPoints")) == 0:  # meshio cannot read an empty piece
        return np.zeros((0, 3)), {}, []
    mesh = meshio.read(folder / name)
    return mesh.points, mesh.point_data, mesh.cells_dict.get("triangle", [])


def plate_axes(inclination_deg: float) -> np.ndarray:
    """R: plate-frame vectors to the world frame (tailbeam.io.paraview.to_world)."""
    t = math.radians(inclination_deg)
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def draw(folder: Path, time: float, inclination: float, out: Path) -> Path:
    from matplotlib.collections import PatchCollection
    from matplotlib.figure import Figure
    from matplotlib.patches import Circle

    times, balls = read_collection(folder / "particles.pvd")
    _, plates = read_collection(folder / "structure.pvd")
    k = int(np.searchsorted(times, time * (1 + 1e-12), side="right") - 1)
    pts, fields, _ = read_frame(folder, balls[k])
    ppts, pfields, tris = read_frame(folder, plates[k])
    rot = plate_axes(inclination)
    local = ppts @ rot  # the plate's points in the plate frame
    fig = Figure(figsize=(11, 4.8), layout="constrained")
    side, face = fig.subplots(1, 2, width_ratios=[1.2, 1])
    colours = [LABEL_COLOURS.get(int(v), "tab:blue") for v in fields.get("label", [])]
    radius = fields.get("radius", np.zeros(0))
    # side view: world x-z, the plate's section through y = 0 as a line
    half = 0.5 * np.ptp(local[:, 0])
    edge = np.array([[-half, 0.0, 0.0], [half, 0.0, 0.0]]) @ rot.T
    side.plot(edge[:, 0], edge[:, 2], color="0.4", lw=3, solid_capstyle="butt")
    side.add_collection(
        PatchCollection([Circle((p[0], p[2]), r) for p, r in zip(pts, radius, strict=True)],
                        facecolors=colours, edgecolors="k", linewidths=0.3)
    )  # fmt: skip
    side.set_aspect("equal")
    side.autoscale_view()
    side.set_xlabel("world x (m)")
    side.set_ylabel("world z, up (m)")
    side.set_title("side view, gravity down\ndiscs: the particles at their radius", fontsize=9)
    # the face, seen along its normal: plate frame x-y
    w = pfields.get("deflection", np.zeros(len(local)))
    lim = float(np.abs(w).max()) or 1.0
    shade = face.tripcolor(local[:, 0], local[:, 1], tris, w * 1e6, cmap="RdBu_r",
                           vmin=-lim * 1e6, vmax=lim * 1e6, shading="gouraud")  # fmt: skip
    fig.colorbar(shade, ax=face, label="plate deflection (um, + away from the plate)")
    mine = pts @ rot  # the particles in the plate frame
    down = mine[:, 2] - radius < TOUCH_GAP if len(mine) else np.zeros(0, dtype=bool)
    for sel, style in ((~down, {"facecolors": "none", "linewidths": 0.8}),
                       (down, {"edgecolors": "k", "linewidths": 0.3})):  # fmt: skip
        discs = [Circle((p[0], p[1]), r) for p, r in zip(mine[sel], radius[sel], strict=True)]
        if "facecolors" in style:
            style = {**style, "edgecolors": [c for c, s in zip(colours, sel, strict=True) if s]}
        else:
            style = {**style, "facecolors": [c for c, s in zip(colours, sel, strict=True) if s]}
        face.add_collection(PatchCollection(discs, **style))
    face.set_aspect("equal")
    face.set_xlabel("plate x, downhill (m)")
    face.set_ylabel("plate y (m)")
    face.set_title(
        f"impact face seen along its normal\nfilled: within {TOUCH_GAP * 1e3:g} mm of it "
        f"({int(down.sum())}); rings: in flight above it ({int((~down).sum())})",
        fontsize=9,
    )
    fig.suptitle(
        f"t = {times[k]:.3f} s: {len(pts)} particles released and not yet gone over an edge "
        f"(dark: coal, orange: gangue); plate inclined {inclination:g} degrees",
        fontsize=10,
    )
    fig.savefig(out, dpi=110)
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("series", type=Path, help="the DIR/vtk folder of a --vtk run")
    parser.add_argument("--time", type=float, default=0.0, help="s (default: 0)")
    parser.add_argument(
        "--inclination", type=float, default=None, help="degrees (default: the run's manifest)"
    )
    parser.add_argument("--out", type=Path, default=Path("frame.png"), help="PNG file")
    args = parser.parse_args(argv)
    if args.inclination is None:
        manifest = json.loads((args.series.parent / "manifest.json").read_text())
        args.inclination = manifest["files"]["vtk/particles.pvd"]["inclination_deg"]
    print(draw(args.series, args.time, args.inclination, args.out))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
