"""The modal plate a solver runs on, set up from the scene in one place: the band, the basis
and its damping, the tail of the modes above the band, and what was chosen.

``single_ball_setup`` chooses the band from the balls' contact pulses and the sensors
(``band.choose_band``) and adds the Ritz tail at the balls' first contact points
(``ritz_prepass``); ``stream_setup`` takes the sensors' band (``band.stream_band``), checks it
against the stream's shortest contacts and builds the contact tails' wider basis. Both say
what they chose on stderr before any long work, and record it for ``Result.info``.
"""

from dataclasses import dataclass, field

import numpy as np

from tailbeam.errors import InputError
from tailbeam.plate.basis import ModalBasis, modal_damping
from tailbeam.plate.contact_tail import ContactTail
from tailbeam.plate.fe.modes import compute_modes
from tailbeam.plate.solid.held import held_structure
from tailbeam.plate.solid.modes import StructureModalBasis, structure_modes
from tailbeam.progress import note
from tailbeam.scene import ModalPlateSettings, Scene
from tailbeam.solvers.modal_setup.band import check_stream_band, choose_band, stream_band
from tailbeam.solvers.modal_setup.ritz_prepass import apply_tail, check_tail_scene, describe_tail

SCENE_FIELDS = {"fmax_hz": "plate.fmax", "divisions": "plate.mesh_divisions"}


@dataclass(frozen=True, eq=False)
class ModalSetup:
    """The modal plate of a scene as a solver takes it.

    Parameters
    ----------
    settings : tailbeam.scene.ModalPlateSettings
        The scene's ``[plate]`` settings (coupling, residual flexibility, ...).
    band : dict
        The band and its estimates (``Result.info["band"]``).
    basis : tailbeam.plate.basis.ModalBasis
        The kept modes (on the single-ball solver with the Ritz tail's pseudo-modes).
    zeta : ndarray
        Damping ratio of each mode of ``basis``.
    tail : dict
        The single-ball solver's tail record (``Result.info["tail"]``; empty for streams).
    contact_tail : tailbeam.plate.contact_tail.ContactTail or None
        The stream's per-contact oscillators, or None (the static spring alone).
    """

    settings: ModalPlateSettings
    band: dict
    basis: ModalBasis
    zeta: np.ndarray
    tail: dict = field(default_factory=dict)
    contact_tail: ContactTail | None = None

    @property
    def two_way(self) -> bool:
        """The balls feel the plate (``plate.coupling = "two-way"``)."""
        return self.settings.coupling == "two-way"

    def info(self) -> dict:
        """What was chosen, for ``Result.info``: ``band``, ``basis`` and (single ball)
        ``tail``."""
        out = choices(self.band, self.basis)
        return {**out, "tail": self.tail} if self.tail else out


def single_ball_setup(scene: Scene, *, basis: ModalBasis | None = None, use_cache=True):
    """The modal plate of a single-ball scene: band from its contacts and sensors, the basis
    (``basis`` if given), the Ritz tail; says what was chosen before the run."""
    settings = scene.modal or ModalPlateSettings()
    check_tail_scene(scene)  # before the basis is built
    band = choose_band(scene, settings)
    if basis is None:
        basis = build_basis(scene, band, use_cache=use_cache)
    basis, tail = apply_tail(scene, basis, settings)
    zeta = modal_damping(basis.omega, settings.damping_ratio, settings.rayleigh)
    setup = ModalSetup(settings, band, basis, zeta, tail=tail)
    note(describe_choices(setup.info()))  # before the run, so a long run says what it runs
    return setup


def stream_setup(scene: Scene) -> ModalSetup:
    """The modal plate of a stream scene: the sensors' band (checked against the stream's
    shortest contacts), its basis and, where they apply, the contact tails."""
    settings = scene.modal or ModalPlateSettings()
    check_tail_scene(scene)  # before any work
    band = stream_band(scene)
    if band["tail_band_hz"] is None and settings.tail != "quasi-static":
        note(f"tail: quasi-static (plate.tail {settings.tail}: {band['tail_reason']})")
    warning = check_stream_band(scene, band)
    if warning:
        note(warning)
    basis = build_basis(scene, band)
    zeta = modal_damping(basis.omega, settings.damping_ratio, settings.rayleigh)
    tail = contact_tail(scene, band, basis) if band["tail_band_hz"] else None
    note(
        f"modal plate under a stream: {band['coupling']}, band 0-{band['fmax_hz'] / 1e3:.1f} "
        f"kHz ({band['reason']}), {basis.theory}, {basis.n_modes} modes"
    )
    return ModalSetup(settings, band, basis, zeta, contact_tail=tail)


def build_basis(scene: Scene, band: dict | None = None, *, use_cache: bool = True):
    """The modal basis of the scene's plate (``tailbeam.plate.fe.modes.compute_modes``) for
    the band (``band.choose_band`` when not given); a band too costly to compute is refused
    naming plate.fmax."""
    settings = scene.modal or ModalPlateSettings()
    band = band or choose_band(scene, settings)
    if settings.mesh is not None:
        return structure_basis(scene, settings, band, use_cache=use_cache)
    try:
        return compute_modes(
            scene.plate, settings.boundary, theory=settings.theory, fmax_hz=band["fmax_hz"],
            divisions=settings.mesh_divisions, use_cache=use_cache,
        )  # fmt: skip
    except InputError as err:
        raise err.renamed(SCENE_FIELDS) from None


def structure_basis(scene: Scene, settings: ModalPlateSettings, band: dict, *,
                    use_cache: bool = True):  # fmt: skip
    """The modes below the band of the scene's structure from ``plate.mesh``
    (``tailbeam.plate.solid``; the model is the one the scene reader built), from the disk
    cache when they were solved before."""
    model = held_structure(settings.mesh, settings.impact_face, settings.supports,
                           scene.plate.material)  # fmt: skip
    basis = structure_modes(model, fmax_hz=band["fmax_hz"], use_cache=use_cache)
    how = {"hit": "read from the cache", "miss": "solved and cached"}.get(
        basis.info["cache"], f"solved (cache {basis.info['cache']})"
    )
    note(
        f"structure from plate.mesh: {model.n_dofs} DOFs, {model.element}; its "
        f"{basis.n_modes} modes to {band['fmax_hz'] / 1e3:g} kHz {how}"
    )
    return basis


def contact_tail(scene: Scene, band: dict, basis: ModalBasis) -> ContactTail:
    """The oscillators of a stream's contacts (``tailbeam.plate.contact_tail``), from a basis
    to the tails' band (``tail_basis``: computed once, cached)."""
    settings = scene.modal
    wide_hz, k = band["tail_band_hz"], band["tail_oscillators"]
    wide = tail_basis(scene, band, basis)
    how = "plate.tail" if settings.tail == "ritz" else "plate.tail auto"
    note(
        f"tail: {k} oscillators at each plate contact for the modes between "
        f"{band['fmax_hz'] / 1e3:g} and {wide_hz / 1e3:g} kHz ({wide.n_modes - basis.n_modes} "
        f"modes; {how}), a static spring for those above"
    )

    def damping(nu):
        return modal_damping(nu, settings.damping_ratio, settings.rayleigh)

    return ContactTail(basis.omega, wide, k, damping)


def tail_basis(scene: Scene, band: dict, basis: ModalBasis) -> ModalBasis:
    """The basis of a stream's contact tails: to band["tail_band_hz"] on the band basis' own
    FE mesh (its modes below the band are the band's; the mesh the wider band alone would
    choose is ~5x larger and takes minutes), or a closed form, or (a structure from
    plate.mesh) the same structure's modes to that band (cached)."""
    wide_hz = band["tail_band_hz"]
    if isinstance(basis, StructureModalBasis):  # the same structure to the tails' band
        return structure_modes(basis.model, fmax_hz=wide_hz)
    if "divisions" not in basis.info:  # a closed form
        return build_basis(scene, {**band, "fmax_hz": wide_hz})
    return compute_modes(scene.plate, basis.boundary, theory=basis.info["theory"],
                         fmax_hz=wide_hz, divisions=basis.info["divisions"])  # fmt: skip


def choices(band: dict, basis: ModalBasis) -> dict:
    """The automatic choices as recorded in ``Result.info`` (band, basis) and impacts.json."""
    described = {
        "theory": basis.theory,
        "boundary": basis.boundary,
        "n_modes": basis.n_modes,
        "top_frequency_hz": float(basis.frequencies_hz[-1]),
        **{k: v for k, v in basis.info.items() if isinstance(v, (str, int, float, bool))},
    }
    cost = basis.info.get("cost_estimate")
    if isinstance(cost, dict):
        described["cost_estimate"] = cost
    return {"band": band, "basis": described}


def describe_choices(info: dict) -> str:
    """One line of what was chosen automatically, from a modal result's ``info``."""
    band, basis = info.get("band", {}), info.get("basis", {})
    if not band:
        return "rigid plate: no modal band"
    parts = [f"band 0-{band['fmax_hz'] / 1e3:.1f} kHz ({band['reason']})"]
    if basis:
        mesh = f", {basis['divisions']} divisions" if basis.get("divisions") else ""
        parts.append(
            f"{basis['theory']}{mesh}, {basis['n_modes']} modes"
            + (f", {basis['n_dofs']} DOFs" if "n_dofs" in basis else "")
            + (f", basis cache {basis['cache']}" if "cache" in basis else "")
        )
    if describe_tail(info.get("tail", {})):
        parts.append(describe_tail(info["tail"]))
    without = " without the Ritz tail" if info.get("tail", {}).get("model") == "ritz" else ""
    parts.append(f"est. peak-force truncation error{without} {band['truncation_force_error']:.1e}")
    if not band["sensor_band_covered"]:
        parts.append("band below a sensor's bandwidth")
    return "; ".join(parts)
