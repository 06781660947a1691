"""A run as a ParaView time series: the particles and the structure at evenly spaced frames.

Two collections (``.pvd``, ParaView's XML index of time steps, written with
``xml.etree.ElementTree``), each of one VTU file per frame (meshio):

- ``particles.pvd``: every body on the plate as a point (a ``vertex`` cell) with the point
  fields ``radius`` (m), ``velocity`` (m/s, 3-vector), ``material`` and ``label`` (integer
  codes: ``material_codes``, ``LABEL_CODES``) and ``id`` (the body's row in particles.csv,
  from 0);
- ``structure.pvd``: the structure's surface with ``displacement`` (m, 3-vector: ParaView's
  "Warp By Vector") and ``deflection`` (m, normal to the impact face, + away from the
  structure); the rigid plate is its undeformed surface, one file listed at every frame.

Frame: world, gravity along -z. The plate frame of the scene (particles.csv, impacts.csv)
turned about its y axis by the inclination: x_world = R x_plate with R's columns the plate's
axes (cos t, 0, -sin t), (0, 1, 0), (sin t, 0, cos t); the origin stays at the centre of the
impact face. For a horizontal plate the two frames are the same.

The structure is anything that follows ``Structure`` (points, cells, and the displacement
field at any times): the flat plate's modes on its FE mesh now (``ModalStructure``); a basis
on a volume or shell mesh plugs in by offering ``vtk_structure()`` (its points, cells and
3-vector mode shapes: ``structure_of``).
"""

import math
import xml.etree.ElementTree as ET
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Protocol

import numpy as np

from tailbeam.errors import InputError
from tailbeam.plate.export import grid_surface, surface
from tailbeam.progress import task
from tailbeam.results.frames import frame_bytes
from tailbeam.scene import LABELS

DEFAULT_RATE_HZ = 200.0
MAX_FRAMES = 5000  # frames per series
MAX_FRAMES_BYTES = 1e9  # the particles' states kept at the frames (BallFrames)
CHUNK_BYTES = 2e8  # the structure's displacements computed at once (frames x points x 3)
LABEL_CODES = {name: code for code, name in enumerate(LABELS)}


class Structure(Protocol):
    """What the series draws as the structure.

    ``points`` (p, 3) m and ``cells`` (meshio cell blocks: [(type, (c, k) int array)]) in the
    plate frame; ``displacement(times)`` (len(times), p, 3) m at ``times`` (s, increasing,
    uniform); ``moves`` False for a structure that never moves (written once)."""

    points: np.ndarray
    cells: list
    moves: bool

    def displacement(self, times) -> np.ndarray: ...


@dataclass(frozen=True, eq=False)
class ModalStructure:
    """A structure moving in its modes: u(x, t) = sum_k shape_k(x) q_k(t).

    Parameters
    ----------
    points : (p, 3) array
        m, plate frame.
    cells : list
        meshio cell blocks.
    shapes : (p, 3, m) array
        The mass-normalised mode shapes at the points, 1/sqrt(kg).
    coordinates : callable
        times (s) -> (m, len(times)) modal coordinates, sqrt(kg) m.
    """

    points: np.ndarray
    cells: list
    shapes: np.ndarray = field(repr=False)
    coordinates: Callable = field(repr=False)
    moves: bool = True

    def displacement(self, times) -> np.ndarray:
        q = self.coordinates(np.asarray(times, dtype=float))
        return np.einsum("pdm,mf->fpd", self.shapes, q)


@dataclass(frozen=True, eq=False)
class StillStructure:
    """A structure that does not move (the rigid plate)."""

    points: np.ndarray
    cells: list
    moves: bool = False

    def displacement(self, times) -> np.ndarray:
        return np.zeros((len(np.atleast_1d(times)), len(self.points), 3))


def structure_of(scene, result) -> Structure:
    """The run's structure: the rigid plate as a rectangle; on the modal plate its kept modes
    (the band) moved by the run's modal coordinates, on the points, cells and 3-vector mode
    shapes the basis gives by ``basis.vtk_structure()`` where it has one (a structure of its
    own mesh), else on the flat plate's FE mesh (``tailbeam.plate.export.surface``, as
    ``tailbeam modes --vtu``). The truncated modes' local quasi-static dent under a contact
    is not in the displacement."""
    if result.plate is None:
        points, tris = grid_surface(scene.plate.size_x, scene.plate.size_y, 1)
        return StillStructure(points, [("triangle", tris)])
    basis = result.plate.basis
    own = getattr(basis, "vtk_structure", None)
    if own is not None:  # (points (p, 3) m, cells, shapes (p, 3, m) 1/sqrt(kg))
        return ModalStructure(*own(), result.plate.modal_coordinates)
    points, tris = surface(basis)
    phi = basis.deflection(points[:, :2])
    shapes = np.zeros((len(points), 3, phi.shape[1]))
    shapes[:, 2, :] = phi
    return ModalStructure(points, [("triangle", tris)], shapes, result.plate.modal_coordinates)


def frame_count(duration: float, rate: float) -> int:
    """How many frames k / ``rate`` (Hz), k = 0, 1, ..., lie within ``duration`` (s)."""
    return int(math.floor(duration * rate * (1.0 + 1e-12))) + 1


def frame_times(duration: float, rate: float) -> np.ndarray:
    """k / ``rate`` (Hz) for k = 0, 1, ... up to ``duration`` (s)."""
    return np.arange(frame_count(duration, rate), dtype=float) / rate


def check_rate(rate, duration: float, n_bodies: int, field_name: str = "--vtk-rate"):
    """The frame times at ``rate`` (Hz) over ``duration`` (s); InputError naming
    ``field_name`` for a rate that is not a number, gives fewer than 2 frames, more than
    MAX_FRAMES, or states of ``n_bodies`` bodies above MAX_FRAMES_BYTES."""
    try:
        rate = float(rate)
    except (TypeError, ValueError):
        raise InputError(field_name, f"must be a frame rate in Hz, got {rate!r}") from None
    if not (math.isfinite(rate) and rate * duration >= 1.0):
        raise InputError(
            field_name, f"must be >= 1/duration = {1.0 / duration:.6g} Hz (2 frames), got {rate!r}"
        )
    if rate * duration >= MAX_FRAMES:  # floor(rate duration) + 1 frames > MAX_FRAMES
        raise InputError(
            field_name,
            f"{rate:g} Hz over {duration:g} s gives {rate * duration + 1:.6g} frames, above "
            f"{MAX_FRAMES}; at most {(MAX_FRAMES - 1) / duration:.6g} Hz",
        )
    n = frame_count(duration, rate)
    need = frame_bytes(n, n_bodies)
    if need > MAX_FRAMES_BYTES:
        raise InputError(
            field_name,
            f"{n} frames of {n_bodies} bodies would keep {need / 1e9:.2f} GB of states, above "
            f"{MAX_FRAMES_BYTES / 1e9:g} GB; lower the rate",
        )
    return frame_times(duration, rate)


def to_world(inclination_deg: float) -> np.ndarray:
    """R (3, 3): plate-frame vectors to the world frame (module docstring)."""
    t = math.radians(inclination_deg)
    c, s = math.cos(t), math.sin(t)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def material_codes(particles) -> dict:
    """Material name -> its integer code in the series (names in sorted order, from 0)."""
    return {name: code for code, name in enumerate(sorted({p.material.name for p in particles}))}


def write_series(folder, scene, result, structure: Structure | None = None) -> list:
    """Write ``result.frames`` and the structure (default ``structure_of``) into ``folder``
    (created); returns the two ``.pvd`` paths."""
    folder = Path(folder)
    folder.mkdir()
    structure = structure if structure is not None else structure_of(scene, result)
    rot = to_world(scene.inclination)
    times = result.frames.times
    with task(f"ParaView series, {len(times)} frames", total=2 * len(times), unit="files") as bar:
        parts = _write_particles(folder, result, rot, bar)
        plate = _write_structure(folder, structure, times, rot, bar)
    return [_write_pvd(folder / "particles.pvd", times, parts),
            _write_pvd(folder / "structure.pvd", times, plate)]  # fmt: skip


def _write_particles(folder: Path, result, rot: np.ndarray, bar) -> list:
    import meshio

    frames, particles = result.frames, result.particles
    codes = material_codes(particles)
    radius = np.array([p.radius for p in particles])
    material = np.array([codes[p.material.name] for p in particles], dtype=np.int32)
    label = np.array([LABEL_CODES.get(p.label, -1) for p in particles], dtype=np.int32)
    names = []
    for k in range(len(frames.times)):
        idx = frames.present(k)
        points = frames.position[k, idx] @ rot.T
        data = {"radius": radius[idx], "velocity": frames.velocity[k, idx] @ rot.T,
                "material": material[idx], "label": label[idx],
                "id": idx.astype(np.int32)}  # fmt: skip
        cells = [("vertex", np.arange(len(idx)).reshape(-1, 1))]
        name = f"particles_{k:05d}.vtu"
        meshio.write(folder / name, meshio.Mesh(points, cells, point_data=data))
        names.append(name)
        bar.update(1)
    return names


def _write_structure(folder: Path, structure: Structure, times, rot: np.ndarray, bar) -> list:
    import meshio

    points = structure.points @ rot.T
    if not structure.moves:
        meshio.write(folder / "structure.vtu", meshio.Mesh(points, structure.cells))
        bar.update(len(times))
        return ["structure.vtu"] * len(times)
    names, chunk_frames = [], max(2, int(CHUNK_BYTES / (24.0 * len(points))))
    for start in range(0, len(times), chunk_frames):
        chunk = structure.displacement(times[start : start + chunk_frames])
        for j, u in enumerate(chunk):
            data = {"displacement": u @ rot.T, "deflection": u[:, 2]}
            name = f"structure_{start + j:05d}.vtu"
            meshio.write(folder / name, meshio.Mesh(points, structure.cells, point_data=data))
            names.append(name)
            bar.update(1)
    return names


def _write_pvd(path: Path, times, files) -> Path:
    """ParaView's collection file: one DataSet per frame (time s, file)."""
    root = ET.Element("VTKFile", type="Collection", version="0.1", byte_order="LittleEndian")
    collection = ET.SubElement(root, "Collection")
    for t, name in zip(times, files, strict=True):
        ET.SubElement(collection, "DataSet", timestep=repr(float(t)), group="", part="0", file=name)
    ET.indent(root)
    ET.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)
    return path
