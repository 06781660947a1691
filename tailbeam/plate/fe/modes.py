"""compute_modes: the plate's natural frequencies and unit-modal-mass mode shapes as a
tailbeam.plate.basis.ModalBasis, from the FE models, with automatic theory/mesh choice and a cache.
"""

import os
import time
from collections import OrderedDict
from dataclasses import dataclass, field, replace
from numbers import Integral

import numpy as np
from skfem import Basis, ElementTriArgyris, ElementTriP3, ElementTriP4, MeshTri
from threadpoolctl import threadpool_limits

from tailbeam.errors import InputError, WorkLimitError, require_positive
from tailbeam.physics.bodies import Plate
from tailbeam.plate import cache as modal_cache
from tailbeam.plate.basis import ModalBasis
from tailbeam.plate.blas import blas_threads as blas_threads_limit
from tailbeam.plate.closed_forms import bending_wavenumber, ssss_kirchhoff_frequencies
from tailbeam.plate.fe.boundary import EDGES, describe, parse_boundary, rigid_body_mode_count
from tailbeam.plate.fe.cost import SolveCost, check_cost, mesh_dofs, solve_cost
from tailbeam.plate.fe.mindlin import DEFAULT_DEGREE
from tailbeam.plate.fe.model import PlateModel, assemble_plate, check_points, resolve_mesh
from tailbeam.plate.fe.resolution import DEFAULT_FMAX_HZ, resolve
from tailbeam.plate.fe.sparse_solve import count_eigenvalues_below, lowest_modes
from tailbeam.plate.probes import PointProbe
from tailbeam.progress import task

MAX_COUNT = 10_000  # modes: far beyond any band this package is meant for
MAX_SOLVE_ROUNDS = 5  # enlarging the number of requested modes until the band is covered
_WEYL_EDGE = {"S": -1.0, "C": -1.0, "F": 1.0}  # boundary term per edge, in units of L k/(4 pi)


def _estimated_count(plate: Plate, boundary: str, theory: str, fmax_hz: float) -> int:
    """Weyl-type estimate of the number of elastic modes below fmax (slightly high)."""
    k = float(bending_wavenumber(plate, fmax_hz, theory))
    area = plate.size_x * plate.size_y
    edge_len = dict(zip(EDGES, (plate.size_y, plate.size_x) * 2, strict=True))
    edge = sum(_WEYL_EDGE[c] * edge_len[e] for e, c in zip(EDGES, boundary, strict=True))
    return int(np.ceil(1.05 * (area * k**2 + edge * k) / (4.0 * np.pi))) + 6


def _check_request(plate, theory, fmax_hz, count):
    if not isinstance(plate, Plate):
        raise InputError("plate", "must be a tailbeam Plate")
    if theory not in ("auto", "kirchhoff", "mindlin"):
        raise InputError("theory", f"must be 'auto', 'kirchhoff' or 'mindlin', got {theory!r}")
    if fmax_hz is not None:
        fmax_hz = require_positive("fmax_hz", fmax_hz)
    if count is not None and (
        isinstance(count, bool) or not isinstance(count, Integral) or count < 1
    ):
        raise InputError("count", f"must be a whole number >= 1, got {count!r}")
    if count is not None and count > MAX_COUNT:
        raise InputError("count", f"must be <= {MAX_COUNT}, got {count!r}")
    if fmax_hz is None and count is None:
        fmax_hz = DEFAULT_FMAX_HZ
    return fmax_hz, None if count is None else int(count)


def _solve_band(model, boundary, fmax_hz, count, on_solve=None):
    """Elastic eigenpairs (lambda, phi) covering the band, rigid-body modes removed."""
    rigid = rigid_body_mode_count(boundary)
    f_scale = float(ssss_kirchhoff_frequencies(model.plate, 1, 1))
    shift = -((2.0 * np.pi * 0.05 * f_scale) ** 2)  # below every eigenvalue, also rigid ones
    wanted = (
        count if fmax_hz is None else _estimated_count(model.plate, boundary, model.theory, fmax_hz)
    )
    if count is not None:
        wanted = min(wanted, count)
    for _ in range(MAX_SOLVE_ROUNDS):
        nev = min(wanted + rigid, model.n_dofs)
        lam, phi = lowest_modes(model.stiffness, model.mass, nev, shift=shift, on_solve=on_solve)
        omega = np.sqrt(np.abs(lam)) * np.sign(lam)
        if rigid:
            # rigid-body modes: numerically zero next to the first elastic frequency
            if omega[rigid - 1] > 1e-3 * max(omega[rigid], 1.0):
                raise WorkLimitError(
                    f"expected {rigid} rigid-body modes for boundary {boundary!r} but the "
                    f"lowest frequencies are {omega[: rigid + 1] / (2 * np.pi)} Hz"
                )
            lam, phi = lam[rigid:], phi[:, rigid:]
        freqs = np.sqrt(np.maximum(lam, 0.0)) / (2.0 * np.pi)
        covered = (count is not None and len(freqs) >= count) or (
            fmax_hz is not None and freqs[-1] > fmax_hz
        )
        if covered or nev == model.n_dofs:
            keep = len(freqs)
            if fmax_hz is not None:
                keep = int(np.searchsorted(freqs, fmax_hz, side="right"))
                # Sylvester's inertia counts the modes below fmax independently of ARPACK
                below = count_eigenvalues_below(
                    model.stiffness, model.mass, (2.0 * np.pi * fmax_hz) ** 2
                )
                if below - rigid > keep and (count is None or keep < count):
                    wanted = int(np.ceil(1.4 * wanted)) + 4
                    continue  # a mode in the band was missed: solve for more
            if count is not None:
                keep = min(keep, count)
            return freqs[:keep], phi[:, :keep]
        wanted = int(np.ceil(1.4 * wanted)) + 4
    raise WorkLimitError(
        f"the band up to {fmax_hz} Hz was not covered after {MAX_SOLVE_ROUNDS} enlargements "
        f"of the eigen-solve ({wanted} modes); ask for fewer modes (count=) or a lower fmax_hz"
    )


def _solve_cost(plate, boundary, res, mesh, fmax_hz, count, degree) -> SolveCost:
    """The estimated work of the solve; InputError naming fmax_hz / count above the limits."""
    n_modes = _estimated_count(plate, boundary, res.theory, res.top_frequency_hz)
    if count is not None:
        n_modes = min(n_modes, count)
    cost = solve_cost(mesh_dofs(mesh, res.theory, degree), n_modes)
    if fmax_hz is not None:
        check_cost(cost, "fmax_hz", f"the band up to {fmax_hz:.0f} Hz", "ask for a lower band")
    else:
        check_cost(cost, "count", f"the first {count} modes", "ask for fewer modes")
    return cost


def _probe_basis(mesh: MeshTri, theory: str, degree: int) -> Basis:
    """A basis only for Basis.probes: a quadrature with no points skips evaluating every
    basis function on every element (0.5 s for Argyris), which probes never use."""
    no_points = (np.zeros((2, 0)), np.zeros(0))
    if theory == "kirchhoff":
        return Basis(mesh, ElementTriArgyris(), quadrature=no_points)
    return Basis(mesh, {3: ElementTriP3, 4: ElementTriP4}[degree](), quadrature=no_points)


@dataclass(frozen=True, eq=False)
class FEModalBasis(ModalBasis):
    """A ModalBasis from the FE model, with what a cross-check needs besides the contract:

    mode_vectors: (n_dofs, n) unit-modal-mass eigenvectors on the model's free DOFs
        (Phi^T M Phi = I, Phi^T K Phi = diag(omega^2));
    mesh: the skfem mesh; fe_model(): the assembled PlateModel (built on first use, shared
        with static_compliance_at).
    ``truncated`` returns a plain ModalBasis (the contract type).
    """

    mode_vectors: np.ndarray | None = None
    mesh: MeshTri | None = None
    _state: dict = field(default_factory=dict, repr=False)

    def fe_model(self) -> PlateModel:
        if self._state.get("model") is None:
            self._state["model"] = assemble_plate(
                self.plate,
                self.boundary,
                theory=self.theory,
                mesh=self.mesh,
                mindlin_degree=self._state["degree"],
            )
        return self._state["model"]


_SHARED_STATES: "OrderedDict[str, dict]" = OrderedDict()
SHARED_MODELS = 2  # assembled FE models kept per process (each ~tens of MB with its LU)
_LOADED: "OrderedDict[tuple, FEModalBasis]" = OrderedDict()  # bases read from the cache


def _shared_state(key, model, degree) -> dict:
    """The state dict of a basis: shared between bases of the same cache ``key`` in this
    process, so the FE model (and its factorisation, used by the residual compliance) is
    assembled once per process, not once per simulation: a sweep's worker runs many cases on
    one basis (measured: 73 % of a 5 kHz single-impact case was rebuilding it)."""
    if key is None:
        return {"model": model, "degree": degree}
    state = _SHARED_STATES.pop(key, None) or {"model": model, "degree": degree}
    if state.get("model") is None:
        state["model"] = model
    _SHARED_STATES[key] = state
    while len(_SHARED_STATES) > SHARED_MODELS:
        _SHARED_STATES.popitem(last=False)
    return state


def _make_basis(
    plate,
    boundary,
    theory,
    freqs,
    vectors,
    free_dofs,
    n_full,
    mesh,
    info,
    *,
    degree,
    model=None,
    probe_basis=None,
    shared_key=None,
):
    """Wrap free-DOF eigenvectors as an FEModalBasis. ``shared_key`` (the cache key): bases of
    the same key in this process share their assembled FE model (see _shared_state)."""
    full = np.zeros((n_full, vectors.shape[1]))
    full[free_dofs] = vectors
    probe = {"basis": probe_basis, "fast": None}

    def deflection_at(points):
        if probe["fast"] is None:
            if probe["basis"] is None:
                probe["basis"] = _probe_basis(mesh, theory, degree)
            probe["fast"] = PointProbe(probe["basis"])
        # the deflection DOFs come first in the vector
        return probe["fast"].values(check_points(plate, points), full)

    basis = FEModalBasis(
        plate=plate,
        frequencies_hz=np.asarray(freqs, dtype=float),
        deflection_at=deflection_at,
        theory=theory,
        boundary=boundary,
        info=info,
        mode_vectors=vectors,
        mesh=mesh,
        _state=_shared_state(shared_key, model, degree),
    )
    if rigid_body_mode_count(boundary) == 0:

        def static_compliance_at(points, contact_radius=0.0):
            return basis.fe_model().static_compliance(points, contact_radius)

        def static_deflection_at(load_point, points, contact_radius=0.0):
            return basis.fe_model().static_deflection(load_point, points, contact_radius)

        object.__setattr__(basis, "static_compliance_at", static_compliance_at)
        object.__setattr__(basis, "static_deflection_at", static_deflection_at)
    return basis


def _from_cache(path, key, plate, boundary, res, accuracy, degree):
    """The cached basis at ``path`` (None on a miss or a damaged entry). A file this process
    already read (same size and modification time) is not read again: its basis is reused
    with this request's ``info`` (a sweep's worker runs many cases on one basis)."""
    try:
        stat = os.stat(path)
    except OSError:
        return None
    memo_key = (str(path), key, stat.st_mtime_ns, stat.st_size)
    basis = _LOADED.pop(memo_key, None)
    if basis is None:
        hit = modal_cache.load(path, key)
        if hit is None:
            return None
        freqs, vectors, free_dofs, n_full, cached_mesh, info = hit
        basis = _make_basis(
            plate,
            boundary,
            res.theory,
            freqs,
            vectors,
            free_dofs,
            n_full,
            cached_mesh,
            info,
            degree=degree,
            shared_key=key,
        )
    _LOADED[memo_key] = basis
    while len(_LOADED) > SHARED_MODELS:
        _LOADED.popitem(last=False)
    # same physics and mesh; the request that led here may differ (e.g. accuracy)
    info = {**basis.info, "cache": "hit", "cache_file": str(path), "reason": res.reason}
    return replace(basis, info={**info, "accuracy": accuracy})


def compute_modes(
    plate: Plate,
    boundary: str = "SSSS",
    *,
    theory: str = "auto",
    fmax_hz: float | None = None,
    count: int | None = None,
    mesh=None,
    divisions=None,
    accuracy: float = 1e-3,
    cache_dir=None,
    use_cache: bool = True,
    mindlin_degree: int = DEFAULT_DEGREE,
    blas_threads: int | None = None,
) -> ModalBasis:
    """Natural frequencies (Hz) and unit-modal-mass shapes of ``plate`` (rigid-body modes
    excluded).

    boundary: four letters C/S/F for the edges left (x=-a/2), bottom (y=-b/2), right (x=+a/2),
    top (y=+b/2). theory: 'kirchhoff', 'mindlin' or 'auto' (chosen from the band and
    ``accuracy``, a relative frequency error; the reason goes into info['reason']).
    Band: modes up to ``fmax_hz`` and/or the first ``count`` (default: up to 10 kHz).
    mesh: a mesh file (named edges left/bottom/right/top) or skfem MeshTri; else ``divisions``
    of the structured mesh; else chosen for ``accuracy``. cache_dir: default
    $TAILBEAM_CACHE_DIR or ~/.cache/tailbeam; use_cache=False neither reads nor writes.
    blas_threads: BLAS thread limit during the solve (``tailbeam.plate.blas.blas_threads``).
    """
    fmax_hz, count = _check_request(plate, theory, fmax_hz, count)
    boundary = parse_boundary(boundary)
    if mesh is not None and divisions is not None:
        raise InputError("divisions", "give either mesh or divisions, not both")
    res = resolve(
        plate,
        theory=theory,
        fmax_hz=fmax_hz,
        count=count,
        accuracy=accuracy,
        user_mesh=mesh is not None,
        divisions=divisions,
    )
    mesh_obj = resolve_mesh(plate, mesh, res.divisions)
    element = "argyris" if res.theory == "kirchhoff" else f"lagrange-p{mindlin_degree}"
    key = modal_cache.cache_key(plate, boundary, res.theory, element, mesh_obj, fmax_hz, count)
    path = modal_cache.cache_path(cache_dir or modal_cache.default_cache_dir(), key)
    if use_cache:
        hit = _from_cache(path, key, plate, boundary, res, accuracy, mindlin_degree)
        if hit is not None:
            return hit
    request = (fmax_hz, count, accuracy, mindlin_degree)
    model, freqs, phi, info = _solve_fresh(plate, boundary, res, mesh, mesh_obj, request,
                                           blas_threads)  # fmt: skip
    info.update(cache="off" if not use_cache else "miss")
    info.update(cache_file=str(path) if use_cache else None)
    if use_cache:
        _store(path, key, freqs, phi, model, mesh_obj, info)
    return _make_basis(plate, boundary, res.theory, freqs, phi, model.free_dofs, model.n_full,
                       mesh_obj, info, degree=mindlin_degree, model=model,
                       shared_key=key if use_cache else None,
                       probe_basis=model.deflection_basis)  # fmt: skip


def _solve_fresh(plate, boundary, res, mesh, mesh_obj, request, blas_threads):
    """Assemble the FE model and solve its band (no cache): (model, frequencies Hz, signed
    free-DOF mode shapes, info). request = (fmax_hz, count, accuracy, mindlin_degree)."""
    fmax_hz, count, accuracy, mindlin_degree = request
    cost = _solve_cost(plate, boundary, res, mesh_obj, fmax_hz, count, mindlin_degree)
    threads = blas_threads_limit(blas_threads)
    with threadpool_limits(limits=threads):
        t0 = time.perf_counter()
        model = assemble_plate(
            plate, boundary, theory=res.theory, mesh=mesh_obj, mindlin_degree=mindlin_degree
        )
        t1 = time.perf_counter()
        with task(f"eigen-solve, {cost.describe()}", unit="solves") as bar:
            freqs, phi = _solve_band(model, boundary, fmax_hz, count, on_solve=bar.update)
        t2 = time.perf_counter()
    if len(freqs) == 0:
        raise InputError(
            "fmax_hz",
            f"no mode lies below {fmax_hz!r} Hz for boundary "
            f"{boundary!r} (the plate's lowest elastic mode is higher)",
        )
    info = _describe(plate, boundary, res, model, mesh, mesh_obj, fmax_hz, count, accuracy)
    info.update(
        {
            "assembly_s": t1 - t0,
            "eigensolve_s": t2 - t1,
            "blas_threads": threads,
            "cost_estimate": cost.as_dict(),
        }
    )
    return model, freqs, _signed(phi), info


def _signed(phi: np.ndarray) -> np.ndarray:
    """Mode vectors (columns) with a reproducible sign: the largest DOF of each is positive."""
    big = np.argmax(np.abs(phi), axis=0)
    signs = np.sign(phi[big, np.arange(phi.shape[1])])
    return phi * np.where(signs == 0, 1.0, signs)


def _describe(plate, boundary, res, model, mesh, mesh_obj, fmax_hz, count, accuracy) -> dict:
    """The basis' info: what was chosen (theory, mesh, band) and why."""
    if mesh is None:
        mesh_text = f"structured, divisions {res.divisions}"
    else:
        mesh_text = "user MeshTri" if isinstance(mesh, MeshTri) else str(mesh)
    return {
        "theory": res.theory,
        "reason": res.reason,
        "element": model.element,
        "boundary": boundary,
        "edges": describe(boundary),
        "mesh": mesh_text,
        "divisions": res.divisions,
        "n_triangles": int(mesh_obj.t.shape[1]),
        "n_dofs": model.n_dofs,
        "fmax_hz": fmax_hz,
        "count": count,
        "accuracy": accuracy,
        "top_frequency_hz": res.top_frequency_hz,
        "predicted_discretisation_error": res.predicted_error,
        "kirchhoff_model_error_at_top": res.kirchhoff_model_error,
        "rigid_body_modes_excluded": rigid_body_mode_count(boundary),
    }


def _store(path, key, freqs, phi, model, mesh_obj, info) -> None:
    """Save the basis in the cache; an unwritable cache is noted in ``info``, not raised (a
    finished computation must not be lost)."""
    try:
        modal_cache.save(path, key, frequencies_hz=freqs, vectors=phi,
                         free_dofs=model.free_dofs, n_full=model.n_full, mesh=mesh_obj,
                         info=info)  # fmt: skip
    except OSError as err:
        info.update(cache=f"not written: {err}", cache_file=None)
