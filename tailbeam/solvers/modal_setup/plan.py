"""The bases a modal scene will need, sized before any of them is computed.

``plan_bases`` takes the band the set-up will choose (``band.choose_band`` for single balls,
``band.stream_band`` for streams), resolves the theory and mesh as ``compute_modes`` will,
counts the DOFs on the mesh and the modes by Weyl's count, and looks the bases up in the
cache: the eigen-solve of the band and, for a stream with contact tails, the tails' wider
basis on the same mesh; for single balls the rest of the set-up (the Ritz tail's pre-pass at
the first contact points, where ``plate.tail`` builds it). The costs are
``tailbeam.solvers.cost.eigen_part`` and ``setup_part``; the main
alternative is the same at half the band (a band set by the sensors' bandwidth: set
``sensors[i].bandwidth``; else ``plate.fmax``).
"""

import math
from dataclasses import dataclass

from tailbeam.errors import InputError
from tailbeam.plate import cache as modal_cache
from tailbeam.plate.fe.boundary import parse_boundary
from tailbeam.plate.fe.cost import check_cost, mesh_dofs, solve_cost
from tailbeam.plate.fe.mindlin import DEFAULT_DEGREE
from tailbeam.plate.fe.model import resolve_mesh
from tailbeam.plate.fe.modes import _estimated_count
from tailbeam.plate.fe.resolution import resolve
from tailbeam.plate.solid import cached as cached_structure
from tailbeam.plate.solid.cost import structure_cost
from tailbeam.plate.solid.face import influence
from tailbeam.plate.solid.held import held_structure
from tailbeam.scene import ModalPlateSettings
from tailbeam.solvers.cost import Part, eigen_part, setup_part, stream_setup_part
from tailbeam.solvers.modal_setup.band import (
    BAND_GRID_HZ,
    STREAM_MIN_BAND_HZ,
    choose_band,
    stream_band,
)
from tailbeam.solvers.modal_setup.ritz_prepass import (
    AUTO_RITZ_BUDGET,
    K_START,
    _unique,
    first_contacts,
)

SCENE_FIELDS = {"fmax_hz": "plate.fmax", "divisions": "plate.mesh_divisions"}

ACCURACY = 1e-3  # compute_modes' default frequency accuracy (the mesh it chooses)


@dataclass(frozen=True)
class BasisPlan:
    """The eigen-solves of a modal scene (``parts``), the band's modes and top (Hz), the
    coupling and contact tails, and the main alternative (one phrase or "")."""

    parts: tuple
    n_modes: int
    fmax_hz: float
    two_way: bool
    tail_oscillators: int
    alternative: str
    n_dofs: int = 0
    ritz_points: int = 0


def plan_bases(scene, stream: bool, band: dict | None = None) -> BasisPlan:
    """The bases of ``scene`` on the set-up ``stream`` (True: the stream solvers') will
    compute, with their estimated costs (module docstring)."""
    settings = scene.modal or ModalPlateSettings()
    band = band or (stream_band(scene) if stream else choose_band(scene, settings))
    fmax = band["fmax_hz"]
    if settings.mesh is not None:
        return _structure_plan(scene, settings, band)
    try:
        dofs, modes, cached, divisions, theory = _size(scene, settings, fmax)
        if cached is None:  # refused as compute_modes would refuse it, before the estimate
            what = f"the band up to {fmax:.0f} Hz"
            check_cost(solve_cost(dofs, modes), "fmax_hz", what, "ask for a lower band")
    except InputError as err:
        raise err.renamed(SCENE_FIELDS) from None
    driver = f"band {fmax / 1e3:g} kHz from {_why(band, stream)}"
    parts = [eigen_part("eigen-solve", dofs, modes, cached, driver)]
    tail_k = 0
    if stream and band.get("tail_band_hz"):
        wide = band["tail_band_hz"]
        t_dofs, t_modes, t_cached, *_ = _size(scene, settings, wide, divisions, theory)
        parts.append(eigen_part("contact tails", t_dofs, t_modes, t_cached,
                                f"modes to {wide / 1e3:g} kHz"))  # fmt: skip
        tail_k = int(band.get("tail_oscillators", 0))
    ritz = 0 if stream else _ritz_points(scene, settings, theory)
    pulses = 0 if band.get("user_fmax") else len(scene.balls)
    parts.append(stream_setup_part() if stream else setup_part(dofs, ritz, pulses))
    two_way = settings.coupling == "two-way"
    return BasisPlan(tuple(parts), modes, fmax, two_way, tail_k,
                     _alternative(scene, settings, band, stream, parts), dofs, ritz)  # fmt: skip


def _structure_plan(scene, settings, band: dict) -> BasisPlan:
    """A structure from plate.mesh: its DOFs and matrices are known (the scene reader built
    it); its eigen-solve is estimated from them (``tailbeam.plate.solid.cost``), and the
    simulation and replay are costed with that estimate's modes."""
    fmax = band["fmax_hz"]
    model = held_structure(settings.mesh, settings.impact_face, settings.supports,
                           scene.plate.material)  # fmt: skip
    cost = structure_cost(model, fmax)
    path = cached_structure.basis_path(None, cached_structure.basis_key(model, fmax, None))
    try:
        size = float(path.stat().st_size)
    except OSError:
        size = None
    driver = (f"structure from plate.mesh, band {fmax / 1e3:g} kHz from "
              f"{_why(band, False)}: {cost.describe()}")  # fmt: skip
    modes = cost.n_modes
    if size is None:
        eigen = Part("eigen-solve", cost.time_s, cost.memory_bytes, driver + ", not cached")
    else:  # the file holds the (n_dofs, modes) float64 vectors
        modes = max(1, int(size // (8 * model.n_dofs)))
        eigen = eigen_part("eigen-solve", model.n_dofs, modes, size, driver + ", cached")
    static = _static_part(model, scene, cost)
    return BasisPlan((eigen, static), modes, fmax, settings.coupling == "two-way", 0, "",
                     model.n_dofs, 0)  # fmt: skip


def _static_part(model, scene, cost) -> Part:
    """The structure's static compliances: read from the cache when it holds the impact
    face's (``structure-face-compliance``) and every sensor channel's influence, else one
    factorisation of K."""
    folder = modal_cache.default_cache_dir()
    key = cached_structure.static_key(model)
    face = modal_cache.entry_path(folder, cached_structure.STATIC_PREFIX, key).is_file()
    channels = [c for s in scene.sensors for c in s.channels()]
    if face and influence.all_cached(model, channels, folder, key):
        return Part("set-up", 0.0, 0.0, "the static compliances, cached", cached=True)
    return Part("set-up", cost.factorise_s, cost.memory_bytes,
                "the static compliance: one factorisation")  # fmt: skip


def _ritz_points(scene, settings, theory: str) -> int:
    """The contact points the single-ball set-up builds the Ritz tail at (0: quasi-static
    tail), as ``ritz_prepass.apply_tail`` decides."""
    if settings.tail == "quasi-static" or not settings.residual_flexibility:
        return 0
    if settings.coupling != "two-way":
        return 0
    points = len(_unique(first_contacts(scene, theory)))
    tail_modes = settings.tail_modes_for(stream=False)
    k = 2 * K_START if tail_modes == "auto" else int(tail_modes)
    if settings.tail == "auto" and k * points > AUTO_RITZ_BUDGET:
        return 0
    return points


def _why(band: dict, stream: bool) -> str:
    if band.get("user_fmax"):
        return "plate.fmax"
    if stream:
        return "the sensors' bandwidth" if band["fmax_hz"] > STREAM_MIN_BAND_HZ else "the minimum"
    return "the sensors' bandwidth" if band["reason"].startswith("sensor") else "the contacts"


def _size(scene, settings, fmax_hz, divisions=None, theory=None):
    """(DOFs, modes, cached file size or None, divisions, theory) of the basis to fmax_hz,
    as ``compute_modes`` would resolve it (``divisions``/``theory``: on that mesh)."""
    plate = scene.plate
    boundary = parse_boundary(settings.boundary)
    res = resolve(plate, theory=theory or settings.theory, fmax_hz=fmax_hz, count=None,
                  accuracy=ACCURACY, user_mesh=False,
                  divisions=divisions or settings.mesh_divisions)  # fmt: skip
    mesh = resolve_mesh(plate, None, res.divisions)
    element = "argyris" if res.theory == "kirchhoff" else f"lagrange-p{DEFAULT_DEGREE}"
    key = modal_cache.cache_key(plate, boundary, res.theory, element, mesh, fmax_hz, None)
    path = modal_cache.cache_path(modal_cache.default_cache_dir(), key)
    try:
        cached = float(path.stat().st_size)
    except OSError:
        cached = None
    modes = _estimated_count(plate, boundary, res.theory, fmax_hz)
    return mesh_dofs(mesh, res.theory, DEFAULT_DEGREE), modes, cached, res.divisions, res.theory


def _alternative(scene, settings, band, stream, parts) -> str:
    """The cost at half the band and the key that sets it, when the eigen-solves are not
    cached and the band is not the user's."""
    solves = [p for p in parts if p.name in ("eigen-solve", "contact tails")]
    if band.get("user_fmax") or all(p.cached for p in solves):
        return ""
    half = BAND_GRID_HZ * math.ceil(band["fmax_hz"] / 2.0 / BAND_GRID_HZ)
    if stream and half < STREAM_MIN_BAND_HZ:
        return ""
    try:
        dofs, modes, cached, *_ = _size(scene, settings, half)
    except InputError:
        return ""
    cost = eigen_part("eigen-solve", dofs, modes, cached, "").time_s
    if stream and band.get("tail_band_hz"):
        cost *= 1.0 + solves[1].time_s / max(solves[0].time_s, 1e-9)  # the tails scale alike
    key = "sensors[i].bandwidth" if _why(band, stream).startswith("the sensors") else "plate.fmax"
    now = sum(p.time_s for p in solves)
    return (f"the bases of {band['fmax_hz'] / 1e3:g} kHz ~{now:.0f} s; {half / 1e3:g} kHz would "
            f"take ~{cost:.0f} s for the bases: set {key}")  # fmt: skip
