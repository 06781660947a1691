"""The manual's figures of the example tail beam (docs/structures.md#the-example-beam), drawn
with matplotlib from tailbeam's own output files (meshio reads the VTK files).

    python tools/beam_figures.py mesh-modes OUT/modes/modes.vtu --out docs/img
    python tools/beam_figures.py frame OUT/beam/vtk --time 2.0 --out docs/img
    python tools/beam_figures.py sensors OUT/beam OUT/flat --out docs/img

``mesh-modes`` (from ``tailbeam modes examples/tail_beam_stream.toml --vtu``): beam-mesh.png,
the hexahedral mesh with its top plate taken off (the ribs inside) and from below (the jack's
patch, the hinge face), and beam-modes.png, the first six modes' vertical displacement on
the impact face. ``frame`` (from ``tailbeam simulate ... --vtk``): beam-frame.png, the
particles on the beam and the impact face's deflection at one time. ``sensors`` (two runs'
sensors.csv): beam-sensor.png, the beam's back sensor against the flat plate's sensor under
the same stream.
"""

import argparse
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

HEX_FACES = ((0, 1, 2, 3), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7))
RIBS_X, RIBS_Y = (-0.3, 0.3), (-0.25, 0.25)  # meshes/tail_beam.py's inner ribs (centre lines)
TOP_PLATE = 0.030  # m
STEEL = (0.62, 0.68, 0.78)


def boundary_faces(cells) -> np.ndarray:
    """(f, 4) the quadrilaterals of hexahedra ``cells`` (c, 8) that belong to one cell only."""
    quads = np.concatenate([cells[:, list(face)] for face in HEX_FACES])
    keys = np.sort(quads, axis=1)
    _, first, counts = np.unique(keys, axis=0, return_index=True, return_counts=True)
    return quads[first[counts == 1]]


def _shaded(ax, points, quads, colours, light=(0.3, -0.5, 0.8)):
    """One collection (so matplotlib sorts all faces together), colours (f, 3) shaded."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    xyz = points[quads]
    normal = np.cross(xyz[:, 1] - xyz[:, 0], xyz[:, 2] - xyz[:, 0])
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    shade = 0.55 + 0.45 * np.abs(normal @ np.asarray(light) / np.linalg.norm(light))
    faces = np.clip(shade[:, None] * np.asarray(colours), 0, 1)
    ax.add_collection3d(Poly3DCollection(xyz, facecolors=faces, edgecolors="0.25",
                                         linewidths=0.15))  # fmt: skip


def _box_axes(ax, points, elev, azim, title):
    lo, hi = points.min(axis=0), points.max(axis=0)
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2] - 0.1, hi[2] + 0.1)
    ax.set_box_aspect((hi[0] - lo[0], hi[1] - lo[1], 0.2 + hi[2] - lo[2]))
    ax.view_init(elev=elev, azim=azim)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_zlabel("z (m)")
    ax.set_title(title, fontsize=10)


def mesh_figure(mesh, out: Path) -> Path:
    import matplotlib.pyplot as plt

    points, cells = mesh.points, mesh.cells_dict["hexahedron"]
    quads = boundary_faces(cells)
    zmin = points[quads][:, :, 2].min(axis=1)
    inside = zmin < -TOP_PLATE - 1e-9  # faces of the ribs and bottom plate, not the top plate
    fig = plt.figure(figsize=(11, 4.6))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    _shaded(ax, points, quads[inside], np.tile(STEEL, (np.count_nonzero(inside), 1)))
    _box_axes(ax, points, 35, -60, "top plate taken off: the ribs and the bottom plate")
    ax = fig.add_subplot(1, 2, 2, projection="3d")
    centre = points[quads].mean(axis=1)
    bottom = np.isclose(centre[:, 2], points[:, 2].min())
    jack = bottom & (centre[:, 0] > -0.2) & (centre[:, 0] < 0.0) & (np.abs(centre[:, 1]) < 0.15)
    hinge = np.isclose(centre[:, 0], points[:, 0].min())
    colours = np.tile(STEEL, (len(quads), 1))
    colours[jack] = (0.85, 0.3, 0.2)
    colours[hinge] = (0.3, 0.65, 0.3)
    _shaded(ax, points, quads, colours)
    _box_axes(ax, points, -30, -130, "from below: jack patch (red), hinge face (green)")
    fig.suptitle(f"meshes/tail_beam.msh: {len(cells)} hexahedra (20-node serendipity), "
                 f"1.8 x 1.5 x 0.30 m", fontsize=11)  # fmt: skip
    fig.tight_layout()
    path = out / "beam-mesh.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def modes_figure(mesh, out: Path, count: int = 6) -> Path:
    import matplotlib.pyplot as plt
    from matplotlib.tri import Triangulation

    points = mesh.points
    top = np.isclose(points[:, 2], 0.0)
    tri = Triangulation(points[top, 0], points[top, 1])
    names = sorted(k for k in mesh.point_data if k.startswith("mode_"))[:count]
    fig, axes = plt.subplots(2, 3, figsize=(11, 6.2), sharex=True, sharey=True)
    for ax, name in zip(axes.ravel(), names, strict=False):
        w = mesh.point_data[name][top, 2]
        w = w / np.max(np.abs(w))
        ax.tricontourf(tri, w, levels=np.linspace(-1, 1, 21), cmap="RdBu_r")
        ax.tricontour(tri, w, levels=[0.0], colors="k", linewidths=0.6)
        for x in RIBS_X:
            ax.axvline(x, color="0.3", ls=":", lw=0.8)
        for y in RIBS_Y:
            ax.axhline(y, color="0.3", ls=":", lw=0.8)
        number, freq = name.split("_")[1], name.split("_")[2].replace("Hz", "")
        ax.set_title(f"mode {int(number)}: {float(freq):.0f} Hz", fontsize=10)
        ax.set_aspect("equal")
    for ax in axes[-1]:
        ax.set_xlabel("x (m), hinge at -0.9")
    for ax in axes[:, 0]:
        ax.set_ylabel("y (m)")
    fig.suptitle("The example beam's first modes: vertical displacement of the impact face "
                 "(normalised, red up, blue down;\nblack: nodal line; dotted: the inner ribs "
                 "below)", fontsize=10)  # fmt: skip
    fig.tight_layout()
    path = out / "beam-modes.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def _nice(value: float) -> float:
    """The smallest of 1, 2, 4, 5 or 8 times a power of ten at or above ``value`` (> 0)."""
    power = 10.0 ** np.floor(np.log10(max(value, 1e-30)))
    return float(next(m * power for m in (1, 2, 4, 5, 8, 10) if m * power >= value))


def _collection(path: Path):
    sets = ET.parse(path).getroot().find("Collection").findall("DataSet")
    return [(float(d.get("timestep")), d.get("file")) for d in sets]


def to_plate(points, inclination_deg: float) -> np.ndarray:
    """World-frame points (p, 3) of the series back in the plate frame (tailbeam.io.paraview:
    x_world = R x_plate, R's columns the plate's axes)."""
    t = np.radians(inclination_deg)
    rot = np.array([[np.cos(t), 0.0, np.sin(t)], [0.0, 1.0, 0.0], [-np.sin(t), 0.0, np.cos(t)]])
    return np.asarray(points) @ rot


def frame_figure(folder: Path, time: float, out: Path, inclination: float = 30.0) -> Path:
    """The particles and the impact face's deflection at the last frame at or before
    ``time``, seen along the face's normal (the plate frame's x-y); particles more than
    5 mm above the face (in flight) drawn hollow."""
    import matplotlib.pyplot as plt
    import meshio
    from matplotlib.collections import PatchCollection
    from matplotlib.patches import Circle
    from matplotlib.tri import Triangulation

    pvds = {p.stem: _collection(p) for p in folder.glob("*.pvd")}
    chosen = {}
    for name, frames in pvds.items():
        before = [f for f in frames if f[0] <= time + 1e-12]
        chosen[name] = before[-1] if before else frames[0]
    fig, ax = plt.subplots(figsize=(8.5, 6.4))
    structure = next((v for k, v in chosen.items() if "particle" not in k), None)
    if structure is not None:
        mesh = meshio.read(folder / structure[1])
        pts = to_plate(mesh.points, inclination)
        w = np.asarray(mesh.point_data["deflection"])
        top = np.abs(pts[:, 2]) < 1e-6
        tri = Triangulation(pts[top, 0], pts[top, 1])
        lim = _nice(np.max(np.abs(w[top])) * 1e6)
        cs = ax.tricontourf(tri, w[top] * 1e6, levels=np.linspace(-lim, lim, 21), cmap="RdBu_r")
        fig.colorbar(cs, ax=ax, label="impact face deflection (um, + up)",
                     ticks=np.linspace(-lim, lim, 9))  # fmt: skip
    particles = next((v for k, v in chosen.items() if "particle" in k), None)
    if particles is not None:
        mesh = meshio.read(folder / particles[1])
        pts = to_plate(mesh.points, inclination)
        radius = np.ravel(mesh.point_data["radius"])
        label = np.ravel(mesh.point_data["label"])
        flying = pts[:, 2] - radius > 5e-3
        for group, face in ((flying, "none"), (~flying, None)):
            discs = [Circle((x, y), r) for (x, y, _), r in zip(pts[group], radius[group],
                                                                  strict=True)]  # fmt: skip
            colours = ["tab:orange" if v else "0.2" for v in label[group]]
            ax.add_collection(PatchCollection(
                discs, facecolors=face or colours, edgecolors=colours, linewidths=0.8,
                alpha=0.85))  # fmt: skip
    ax.set_aspect("equal")
    ax.set_xlim(-0.9, 0.9)
    ax.set_ylim(-0.75, 0.75)
    ax.set_xlabel("x (m, downhill; hinge at -0.9)")
    ax.set_ylabel("y (m)")
    t = structure[0] if structure else particles[0]
    ax.set_title(f"The caving stream on the example beam at t = {t:.2f} s, seen along the "
                 "face's normal\n(coal dark, gangue orange, at their radii; hollow: in flight)",
                 fontsize=10)  # fmt: skip
    fig.tight_layout()
    path = out / "beam-frame.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def sensors_figure(beam: Path, flat: Path, out: Path, beam_channel="back", flat_channel="S1"):
    import matplotlib.pyplot as plt

    def read(folder, channel):
        data = np.genfromtxt(folder / "sensors.csv", delimiter=",", names=True)
        return data["t"], data[channel]

    fig, axes = plt.subplots(2, 1, figsize=(10, 5.6), sharex=True)
    for ax, (folder, channel, what) in zip(axes, [
        (beam, beam_channel, f"beam, back sensor '{beam_channel}' (bottom plate, x = 0.45 m)"),
        (flat, flat_channel, f"flat 0.6 x 0.6 x 0.01 m SSSS plate, sensor '{flat_channel}'"),
    ], strict=True):  # fmt: skip
        t, a = read(folder, channel)
        ax.plot(t, a, lw=0.4)
        ax.set_ylabel("acceleration (m/s^2)")
        rms = np.sqrt(np.mean(a**2))
        ax.set_title(f"{what}: peak {np.max(np.abs(a)):.3g}, RMS {rms:.3g} m/s^2 "
                     "(own scale)", fontsize=10)  # fmt: skip
    axes[-1].set_xlabel("t (s)")
    fig.suptitle("The same caving stream (200 lumps per second, radii 10-40 mm), modes to 2 kHz, "
                 "sensors through their chain", fontsize=11)  # fmt: skip
    fig.tight_layout()
    path = out / "beam-sensor.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(argv=None) -> int:
    import matplotlib

    matplotlib.use("Agg")
    import meshio

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="what", required=True)
    a = sub.add_parser("mesh-modes")
    a.add_argument("vtu", type=Path)
    b = sub.add_parser("frame")
    b.add_argument("folder", type=Path)
    b.add_argument("--time", type=float, default=2.0)
    b.add_argument("--inclination", type=float, default=30.0, help="degrees (the scene's)")
    c = sub.add_parser("sensors")
    c.add_argument("beam", type=Path)
    c.add_argument("flat", type=Path)
    for p in (a, b, c):
        p.add_argument("--out", type=Path, default=Path("docs/img"))
    args = parser.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    if args.what == "mesh-modes":
        mesh = meshio.read(args.vtu)
        print(mesh_figure(mesh, args.out), modes_figure(mesh, args.out))
    elif args.what == "frame":
        print(frame_figure(args.folder, args.time, args.out, args.inclination))
    else:
        print(sensors_figure(args.beam, args.flat, args.out))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
