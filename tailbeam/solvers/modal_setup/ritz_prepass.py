"""The Ritz tail of the coupled solver (``plate.tail = "ritz"``, and the default "auto" where
it applies: ``apply_tail``): a pre-pass over the balls' first contact points that adds
load-dependent Ritz pseudo-modes of the truncated modes there (tailbeam.plate.ritz_tail) to
the modal basis before the run.

The first contact of every ball is known in closed form on the horizontal plate: free fall z(t) =
gap + vz t - g t^2 / 2 of the ball's lowest point to the undeformed plate, at (x0 + vx t_hit, y0 +
vy t_hit) (a ball dropped vertically hits at (x0, y0)). Balls that do not reach the plate within
the scene's duration, or land off it, add no point. Each point keeps the load radius of its ball's
load model (tailbeam.physics.contact_patch.load_radius, already rounded to the solver's 5 % grid),
so equal (point, radius) pairs are built once; different radii are separate columns of ONE block
Krylov build (``with_ritz_tail`` with one radius per point).

The pseudo-modes are ordinary modes of the augmented basis (true shapes, K- and M-orthogonal
to the kept modes), so everything downstream holds them: the residual compliance at any
contact (later contacts elsewhere keep the quasi-static residual of the augmented basis,
static minus every mode held), and the sensors' quasi-static correction (the residual cross
compliance of the augmented basis), without double counting.

k per point: ``plate.tail_modes`` (a whole number, default 32), or "auto": ``choose_ritz_k``
per point from the Hertz estimate of the ball's first impact on a rigid plate (duration, peak
force, maximum penetration at the speed after its fall), tolerance AUTO_TOL; the block uses
the largest k.
"""

import math
import time

from tailbeam.errors import InputError, WorkLimitError
from tailbeam.physics.contact_patch import load_radius
from tailbeam.physics.hertz import hertz_contact_duration, hertz_max_penetration, hertz_peak_force
from tailbeam.plate import ritz_tail
from tailbeam.plate.ritz_tail import K_START, MAX_RITZ_VECTORS, choose_ritz_k, with_ritz_tail
from tailbeam.progress import note, task
from tailbeam.scene import DEFAULT_TAIL_MODES, STREAM_TAIL_MODES

AUTO_TOL = 1e-5  # choose_ritz_k's tolerance (relative to the max penetration)
AUTO_RITZ_BUDGET = 128  # pseudo-modes (k x points) plate.tail = "auto" builds at most
AUTO_K_MAX = 512  # choose_ritz_k's k_max per point (fewer if the points share MAX_RITZ_VECTORS)
MIN_SPEED = 1e-3  # m/s, the impact speed floor of the band's contact estimate (auto.py)


def first_contact_time(gap: float, vz: float, gravity: float) -> float:
    """Time (s) for a ball's lowest point ``gap`` m above the plate, with vertical velocity
    ``vz`` m/s (up positive) under ``gravity`` m/s^2, to reach the plate; inf if never."""
    if gap <= 0.0:
        return 0.0
    if gravity > 0.0:
        return (vz + math.sqrt(vz * vz + 2.0 * gravity * gap)) / gravity
    return gap / -vz if vz < 0.0 else math.inf


def first_contacts(scene, theory: str) -> list:
    """The balls' first contacts within the scene's duration on the plate: a list of dicts
    ball (name), point (x, y) m, radius (m, the load model's), speed (m/s, at impact)."""
    out = []
    for ball, law in zip(scene.balls, scene.laws(), strict=True):
        (x0, y0, _), (vx, vy, vz) = ball.position, ball.velocity
        t = first_contact_time(ball.gap, vz, scene.gravity)
        point = (x0 + vx * t, y0 + vy * t)
        if t > scene.duration or not scene.plate.contains(*point):
            continue
        speed = math.sqrt(vz * vz + 2.0 * scene.gravity * max(ball.gap, 0.0))
        out.append({
            "ball": ball.name,
            "point": point,
            "radius": load_radius(theory, ball, law, scene.gravity),
            "speed": max(speed, MIN_SPEED),
            "law": law,
            "mass": ball.mass,
        })  # fmt: skip
    return out


def _unique(contacts) -> list:
    """The contacts with distinct (point, radius), first of each kept."""
    seen, out = set(), []
    for c in contacts:
        key = (round(c["point"][0], 12), round(c["point"][1], 12), c["radius"])
        if key not in seen:
            seen.add(key)
            out.append(c)
    return out


def _check_basis(basis) -> None:
    ritz_tail.check_fe_basis(
        basis,
        "plate.tail",
        f"'ritz' needs the FE modes and model; the {basis.theory} {basis.boundary} basis "
        "has none (closed form); set plate.tail = 'quasi-static'",
    )


def _auto_k(basis, points) -> tuple[int, list]:
    """choose_ritz_k for every point (Hertz estimate of its impact): the block's k (the
    largest) and each point's (k, change)."""
    k_max = min(AUTO_K_MAX, MAX_RITZ_VECTORS // len(points))
    if k_max < 2 * K_START:
        raise WorkLimitError(
            f"plate.tail_modes: 'auto' needs k up to >= {2 * K_START} per point; {len(points)} "
            f"points share {MAX_RITZ_VECTORS} Ritz vectors; set plate.tail_modes to a number "
            f"<= {MAX_RITZ_VECTORS // len(points)} or use fewer balls"
        )
    chosen = []
    with task("Ritz tail: choosing k per contact point", total=len(points), unit="points") as bar:
        for c in points:
            m, v, law = c["mass"], c["speed"], c["law"]
            estimate = (
                hertz_contact_duration(m, v, law.stiffness, law.exponent),
                hertz_peak_force(m, v, law.stiffness, law.exponent),
                hertz_max_penetration(m, v, law.stiffness, law.exponent),
            )
            try:
                chosen.append(choose_ritz_k(basis, c["point"], c["radius"], *estimate,
                                            tol=AUTO_TOL, k_max=k_max))  # fmt: skip
            except WorkLimitError:
                raise WorkLimitError(
                    f"plate.tail_modes: 'auto' found no k <= {k_max} with a tail change below "
                    f"{AUTO_TOL:g} at {c['ball']}'s contact; set plate.tail_modes to a number"
                ) from None
            bar.update(1)
    return max(k for k, _ in chosen), chosen


def ritz_tail_basis(scene, basis, tail_modes="auto"):
    """``basis`` plus the Ritz tail at the balls' first contact points, and the record of
    what was built (result.info["tail"]). InputError naming plate.tail if the basis has no
    FE model; WorkLimitError naming plate.tail_modes if k x points > MAX_RITZ_VECTORS."""
    _check_basis(basis)
    contacts = first_contacts(scene, basis.theory)
    points = _unique(contacts)
    info = {"model": "ritz", "tail_modes": tail_modes, "points": len(points), "added_modes": 0}
    if not points:
        note("Ritz tail: no ball reaches the plate within the duration; quasi-static tail only")
        return basis, info
    started = time.perf_counter()
    if tail_modes == "auto":
        k, chosen = _auto_k(basis, points)
        info["k_per_point"] = [int(kk) for kk, _ in chosen]
        info["k_change_per_point"] = [float(ch) for _, ch in chosen]
    else:
        k = int(tail_modes)
    _check_work(k, len(points))
    xy = [c["point"] for c in points]
    radii = [c["radius"] for c in points]
    with task(f"Ritz tail: {k} x {len(points)} pseudo-modes"):
        augmented = with_ritz_tail(basis, xy, radii, k)
    added = augmented.n_modes - basis.n_modes
    info.update(k=int(k), added_modes=int(added), build_s=time.perf_counter() - started,
                contact_points=[list(map(float, p)) for p in xy], load_radii_m=radii)  # fmt: skip
    how = "auto, largest over the points" if tail_modes == "auto" else "plate.tail_modes"
    how += ", the default" if tail_modes == DEFAULT_TAIL_MODES else ""
    note(
        f"Ritz tail: k = {k} ({how}) at {len(points)} first-contact point(s), "
        f"{added} pseudo-modes added to {basis.n_modes} modes"
    )
    return augmented, info


def apply_tail(scene, basis, settings):
    """The basis the coupled solver runs on and result.info["tail"], from ``settings.tail``
    (the scene's ``ModalPlateSettings``):
    "ritz" builds the Ritz tail (errors name plate.tail / plate.tail_modes), "quasi-static"
    keeps ``basis``, "auto" builds it where it applies and otherwise keeps ``basis`` with
    the reason (said on stderr): a basis without an FE model (closed form), residual
    flexibility off, one-way coupling, more pseudo-modes than AUTO_RITZ_BUDGET (many
    balls) or than MAX_RITZ_VECTORS."""
    tail_modes = settings.tail_modes_for(stream=False)
    if settings.tail == "ritz":
        return ritz_tail_basis(scene, basis, tail_modes)
    if settings.tail == "quasi-static":
        return basis, {"model": "quasi-static", "reason": "plate.tail"}
    why = _why_not_ritz(settings, basis) or _over_budget(scene, basis, tail_modes)
    if why is None:
        try:
            return ritz_tail_basis(scene, basis, tail_modes)
        except WorkLimitError as err:
            why = str(err)
    note(f"tail: quasi-static ({why})")
    return basis, {"model": "quasi-static", "reason": why}


def _why_not_ritz(settings, basis) -> str | None:
    """Why plate.tail = "auto" keeps the quasi-static tail, or None if the Ritz tail applies."""
    if not settings.residual_flexibility:
        return "plate.residual_flexibility is off"
    if settings.coupling != "two-way":
        return "one-way coupling"
    if basis.theory == "solid":
        return "the Ritz tail is not built on a structure from a mesh yet"
    try:
        ritz_tail.check_fe_basis(basis)
    except InputError:
        return f"the {basis.theory} {basis.boundary} basis is a closed form, without an FE model"
    return None


def _over_budget(scene, basis, tail_modes) -> str | None:
    """Why "auto" keeps the quasi-static tail for a scene with many first contacts, or None:
    more than AUTO_RITZ_BUDGET pseudo-modes (k x points; k >= 2 K_START for "auto") would
    cost more than the run (30 balls on the default plate: 32 s of pre-pass and 960 more
    modes against a 6 s quasi-static run)."""
    points = len(_unique(first_contacts(scene, basis.theory)))
    k = 2 * K_START if tail_modes == "auto" else int(tail_modes)
    if k * points <= AUTO_RITZ_BUDGET:
        return None
    return (
        f"{points} first-contact points x {k} pseudo-modes > {AUTO_RITZ_BUDGET}, more than the "
        "run would cost; plate.tail = 'ritz' forces the Ritz tail"
    )


def describe_tail(info: dict) -> str:
    """One phrase for describe_choices: the tail model."""
    if info.get("model") == "quasi-static":
        return "" if info.get("reason") == "plate.tail" else "quasi-static tail"
    if info.get("model") != "ritz":
        return ""
    return f"Ritz tail k = {info.get('k', 0)}, +{info['added_modes']} modes"


def check_tail_scene(scene) -> None:
    """Before any work: InputError naming plate.tail_modes for "auto" on the stream solver
    (its contacts take a number of oscillators) unless plate.tail is "quasi-static";
    WorkLimitError naming plate.tail_modes if a set k x the first-contact points exceeds
    MAX_RITZ_VECTORS (the coupled solver with plate.tail = "ritz")."""
    settings = scene.modal
    if settings is None or settings.tail == "quasi-static":
        return
    if settings.tail == "ritz" and settings.mesh is not None and not scene.needs_stream_solver:
        raise InputError(
            "plate.tail",
            "'ritz' is not built on a structure from plate.mesh for single balls; use "
            "'quasi-static' or 'auto' (its residual flexibility is the structure's static "
            "compliance)",
        )
    if scene.needs_stream_solver:
        if settings.tail_modes == "auto":
            raise InputError(
                "plate.tail_modes",
                "'auto' is the coupled solver's; on the stream solver (streams, an inclined "
                "plate or balls that may touch) set a number of oscillators per contact "
                f"(default {STREAM_TAIL_MODES})",
            )
        return
    tail_modes = settings.tail_modes_for(stream=False)
    if settings.tail == "ritz" and tail_modes != "auto":
        _check_work(tail_modes, len(_unique(first_contacts(scene, "kirchhoff"))))


def _check_work(k: int, n_points: int) -> None:
    if k * n_points > MAX_RITZ_VECTORS:
        raise WorkLimitError(
            f"plate.tail_modes: {k} Ritz modes x {n_points} contact points > "
            f"{MAX_RITZ_VECTORS}; lower plate.tail_modes or use fewer balls"
        )
