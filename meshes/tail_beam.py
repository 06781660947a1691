"""The example tail beam: a welded box of steel plates with longitudinal and transverse ribs,
meshed in hexahedra by Gmsh (``pip install tailbeam[mesh]``), written to meshes/tail_beam.msh.

    python meshes/tail_beam.py [--size 0.05] [--out meshes/tail_beam.msh]
                               [--top 0.030] [--bottom 0.025] [--rib 0.020]

Dimensions (m). They are representative of a top-coal caving support's tail beam as the
literature describes it (a box of 20-40 mm plates, about as wide as the support, hinged to the
shield, held up by the tail-beam jack), chosen within those ranges, not copied from one
manufacturer's drawing: width 1.5 (a 1.5 m support spacing), length 1.8 from the hinge to the
tip, depth 0.30; top plate 30 mm (the impact face), bottom plate 25 mm; four longitudinal
ribs 20 mm (the two side webs and two inner ribs at y = +-0.25); four transverse ribs 20 mm
(the two end plates and two inner ribs at x = +-0.3). Change them below and run the script,
or give the plates' and ribs' thicknesses as options (``--top``, ``--bottom``, ``--rib``): a
sweep over ``plate.mesh`` runs a list of such meshes (docs/datasets.md).

Frame (the plate frame of tailbeam): the top face is z = 0, centred on the origin, x along
the beam (hinge end x = -0.9, tip x = +0.9), y across, the box below (z from -0.30 to 0).

Named groups: ``top`` (the impact face), ``hinge`` (the whole hinge-end face, x = -0.9: a
``pinned`` support there turns about the y axis through its centroid), ``jack`` (the patch
of the bottom plate where the jack's head pushes: x in [-0.2, 0], |y| <= 0.15), and the
volume ``steel``.

Meshing: the structure is a union of rectangular blocks of a tensor grid, so every block is
meshed by transfinite hexahedra (one element through each plate's thickness, about ``--size``
in the plane; see docs/structures.md for why one layer of quadratic hexahedra suffices).
"""

import argparse
import itertools
import math
from dataclasses import dataclass
from pathlib import Path

WIDTH, LENGTH, DEPTH = 1.5, 1.8, 0.30
TOP, BOTTOM, RIB = 0.030, 0.025, 0.020
LONGITUDINAL_RIBS_Y = (-0.25, 0.25)  # centre lines of the inner longitudinal ribs
TRANSVERSE_RIBS_X = (-0.3, 0.3)  # centre lines of the inner transverse ribs
JACK_X, JACK_HALF_Y = (-0.2, 0.0), 0.15  # the jack's bearing patch on the bottom plate
DEFAULT_SIZE = 0.05  # in-plane element size, m
MAX_RIB = 0.1  # m: thicker ribs would cross the jack patch's edges and each other


@dataclass(frozen=True)
class Plates:
    """The thicknesses (m) of the top plate, the bottom plate and every rib."""

    top: float = TOP
    bottom: float = BOTTOM
    rib: float = RIB


def breaks(plates: Plates = Plates()):
    """The tensor grid's x, y, z break points: every plate face and the jack patch."""
    hx, hy, rib = 0.5 * LENGTH, 0.5 * WIDTH, plates.rib
    xs = {-hx, -hx + rib, hx - rib, hx, *JACK_X}
    for x in TRANSVERSE_RIBS_X:
        xs |= {x - 0.5 * rib, x + 0.5 * rib}
    ys = {-hy, -hy + rib, hy - rib, hy, -JACK_HALF_Y, JACK_HALF_Y}
    for y in LONGITUDINAL_RIBS_Y:
        ys |= {y - 0.5 * rib, y + 0.5 * rib}
    zs = {-DEPTH, -DEPTH + plates.bottom, -plates.top, 0.0}
    return sorted(xs), sorted(ys), sorted(zs)


def is_steel(x, y, z, plates: Plates = Plates()) -> bool:
    """Whether the block with centre (x, y, z) is steel (a plate or a rib), not the hollow."""
    hx, hy, rib = 0.5 * LENGTH, 0.5 * WIDTH, plates.rib
    in_plate = z > -plates.top or z < -DEPTH + plates.bottom
    in_web = abs(y) > hy - rib or any(abs(y - r) < 0.5 * rib for r in LONGITUDINAL_RIBS_Y)
    in_rib = abs(x) > hx - rib or any(abs(x - r) < 0.5 * rib for r in TRANSVERSE_RIBS_X)
    return in_plate or in_web or in_rib


def build(size: float, plates: Plates = Plates()):
    """Create the geometry in the current gmsh model; returns the named face lists."""
    import gmsh

    geo = gmsh.model.geo
    xs, ys, zs = breaks(plates)
    grid = (xs, ys, zs)
    points, lines, faces = {}, {}, {}

    def point(i, j, k):
        if (i, j, k) not in points:
            points[i, j, k] = geo.addPoint(xs[i], ys[j], zs[k])
        return points[i, j, k]

    def line(a, b):  # a, b grid indices differing in one axis by one
        key = (a, b)
        if key not in lines:
            lines[key] = geo.addLine(point(*a), point(*b))
            axis = next(n for n in range(3) if a[n] != b[n])
            span = grid[axis][b[axis]] - grid[axis][a[axis]]
            geo.mesh.setTransfiniteCurve(lines[key], max(1, math.ceil(span / size - 1e-9)) + 1)
        return lines[key]

    def face(corner, u, v):  # the quad at grid corner spanned by unit steps u, v
        key = (corner, u, v)
        if key not in faces:
            a = corner
            b = tuple(c + d for c, d in zip(a, u, strict=True))
            c = tuple(p + q for p, q in zip(b, v, strict=True))
            d = tuple(p + q for p, q in zip(a, v, strict=True))
            loop = geo.addCurveLoop([line(a, b), line(b, c), -line(d, c), -line(a, d)])
            faces[key] = geo.addPlaneSurface([loop])
            geo.mesh.setTransfiniteSurface(faces[key])
            geo.mesh.setRecombine(2, faces[key])
        return faces[key]

    ex, ey, ez = (1, 0, 0), (0, 1, 0), (0, 0, 1)
    blocks, named = [], {"top": [], "hinge": [], "jack": []}
    for i, j, k in itertools.product(range(len(xs) - 1), range(len(ys) - 1), range(len(zs) - 1)):
        centre = (0.5 * (xs[i] + xs[i + 1]), 0.5 * (ys[j] + ys[j + 1]), 0.5 * (zs[k] + zs[k + 1]))
        if not is_steel(*centre, plates):
            continue
        sides = [face((i, j, k), ex, ey), face((i, j, k + 1), ex, ey),
                 face((i, j, k), ex, ez), face((i, j + 1, k), ex, ez),
                 face((i, j, k), ey, ez), face((i + 1, j, k), ey, ez)]  # fmt: skip
        loop = geo.addSurfaceLoop(sides)
        blocks.append(geo.addVolume([loop]))
        geo.mesh.setTransfiniteVolume(blocks[-1])
        if k == len(zs) - 2:
            named["top"].append(sides[1])
        if i == 0:
            named["hinge"].append(sides[4])
        if k == 0 and JACK_X[0] <= centre[0] <= JACK_X[1] and abs(centre[1]) <= JACK_HALF_Y:
            named["jack"].append(sides[0])
    return blocks, named


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", type=float, default=DEFAULT_SIZE, help="in-plane element size, m")
    parser.add_argument("--out", type=Path, default=Path(__file__).with_name("tail_beam.msh"))
    for name, value, what in (("top", TOP, "top plate (the impact face)"),
                              ("bottom", BOTTOM, "bottom plate"),
                              ("rib", RIB, "every rib, longitudinal and transverse")):  # fmt: skip
        parser.add_argument(f"--{name}", type=float, default=value,
                            help=f"thickness of the {what}, m (default {value})")  # fmt: skip
    args = parser.parse_args(argv)
    plates = Plates(args.top, args.bottom, args.rib)
    _check(parser, args.size, plates)
    import gmsh

    gmsh.initialize()
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.add("tail_beam")
        blocks, named = build(args.size, plates)
        gmsh.model.geo.synchronize()
        gmsh.model.addPhysicalGroup(3, blocks, name="steel")
        for name, tags in named.items():
            gmsh.model.addPhysicalGroup(2, tags, name=name)
        gmsh.option.setNumber("Mesh.RecombineAll", 1)
        gmsh.model.mesh.generate(3)
        gmsh.model.mesh.removeDuplicateNodes()
        gmsh.option.setNumber("Mesh.MshFileVersion", 4.1)
        gmsh.option.setNumber("Mesh.Binary", 1)
        gmsh.write(str(args.out))
        n_nodes = len(gmsh.model.mesh.getNodes()[0])
    finally:
        gmsh.finalize()
    print(f"wrote {args.out}: {len(blocks)} blocks, {n_nodes} nodes")


def _check(parser, size: float, plates: Plates) -> None:
    """Every size and thickness > 0, the plates thinner than the depth and the ribs than
    MAX_RIB (argparse's one-line error, exit 2)."""
    for name, value in (("size", size), ("top", plates.top), ("bottom", plates.bottom),
                        ("rib", plates.rib)):  # fmt: skip
        if not value > 0:
            parser.error(f"--{name}: must be > 0 m, got {value}")
    if plates.top + plates.bottom >= DEPTH:
        parser.error(f"--top + --bottom: must be below the depth {DEPTH} m")
    if plates.rib >= MAX_RIB:
        parser.error(f"--rib: must be below {MAX_RIB} m (the ribs and the jack patch may not meet)")


if __name__ == "__main__":
    main()
