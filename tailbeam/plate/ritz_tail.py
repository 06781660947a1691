"""Load-dependent Ritz pseudo-modes of the modes a band leaves out, at fixed load points.

A modal basis cut at a band edge leaves out the "tail" of the spectrum. At a contact the tail
acts through its spectral measure sum_i (phi_i . f)^2 delta(lambda - lambda_i) (f the
contact's load vector). The quasi-static residual keeps only its first moment (the static
compliance); k load-dependent Ritz vectors (Wilson, Yuan and Dickens 1982) keep 2k moments:
the Krylov space of K^-1 M started from the static residual K^-1 f - sum_kept phi phi^T f /
omega^2, M-orthogonal to the kept modes, then Rayleigh-Ritz on (K, M). The k Ritz pairs are
the k-node Gauss rule of the tail's measure in s = 1/lambda with weights (phi . f)^2 / lambda,
so sum (z . f)^2 / omega^(2m+2) equals the tail's sum (phi . f)^2 / lambda^(m+1) for
m < 2k. The vectors are K- and M-orthogonal to the kept modes and to each other, so they are
ordinary extra modes (Rayleigh damping stays diagonal) with true plate shapes.

Measured (docs/fe-convergence.md, "Many-node tails"): at a 20 kHz band, k = 16-32 per contact
point brings the contact quantities of the test meshes to 2-7e-6 of the full FE solution
(quasi-static residual 3.5e-5), k = 48-128 on the default Argyris 23x23 mesh. This module only
builds them for load points known in advance (``with_ritz_tail``: the FE cross-checks, and
the coupled solver's pre-pass over the balls' first contact points with ``plate.tail =
"ritz"``, tailbeam.solvers.modal_setup.ritz_prepass).
"""

import numpy as np
from scipy.linalg import eigh

from tailbeam.errors import InputError, WorkLimitError, require_nonnegative, require_positive
from tailbeam.plate.basis import ModalBasis
from tailbeam.plate.blas import limited
from tailbeam.plate.fe.model import check_points

MAX_RITZ_VECTORS = 1024  # k x points: memory n_dofs x this x 8 B (250 MB at 30 000 DOFs)
K_START = 16  # choose_ritz_k's first k (fewer ring coherently: docs/fe-convergence.md)
DEFLECTION_MEMO = 32  # point sets whose deflections with_ritz_tail's basis keeps
BREAKDOWN = 1e-10  # a new Krylov vector this small against its start is dropped (exhausted)
KRYLOV_MEMO = 2  # Krylov spaces kept (the last loads): choose_ritz_k's space serves the build


def ritz_tail_modes(basis, loads, k: int):
    """Ritz pseudo-modes of ``basis``' truncated modes for the load vectors ``loads``.

    basis: a ``FEModalBasis`` (``compute_modes``): its mode vectors (M-orthonormal, the kept
        modes) and its FE model (K, M and the factorised K).
    loads: (n_dofs, p) load vectors (N per unit force, ``PlateModel.load_vector``).
    k: Krylov steps per load (block size p): up to k p pseudo-modes, fewer if the Krylov
        space is exhausted.

    Returns omega (m,) rad/s ascending and Z (n_dofs, m), Z^T M Z = I, Z^T K Z = diag(omega^2),
    Phi_kept^T M Z = 0.
    """
    return krylov_tail(basis, loads).modes(k)


_KRYLOV: dict = {}  # (id(basis), loads bytes) -> (basis, KrylovTail), the last KRYLOV_MEMO


def krylov_tail(basis, loads) -> "KrylovTail":
    """The Krylov space of ``loads`` on ``basis``, shared by the calls that ask for the same
    loads (choose_ritz_k grows it to 2k; the build with k then only projects it)."""
    loads = np.asarray(loads, dtype=float)
    key = (id(basis), loads.shape, loads.tobytes())
    return _remember(_KRYLOV, key, basis, lambda: KrylovTail(basis, loads))


def _remember(store: dict, key, owner, build):
    """``store[key]``'s value if it was built for this very ``owner`` object (ids are reused
    once an object is gone), else ``build()`` kept there; the store holds the last
    KRYLOV_MEMO."""
    hit = store.get(key)
    if hit is None or hit[0] is not owner:
        while len(store) >= KRYLOV_MEMO:
            store.pop(next(iter(store)))
        hit = store[key] = (owner, build())
    return hit[1]


class KrylovTail:
    """The block Krylov space of K^-1 M started from ``loads``' static residual, M-orthogonal
    to ``basis``' kept modes, grown step by step: the space of k steps is the start of the
    space of 2k steps (the same vectors, bit for bit), so trying k = 16, 32, 64, ... costs one
    build to the largest k, not the sum (``choose_ritz_k``)."""

    def __init__(self, basis, loads):
        self.model, self.kept = basis.fe_model(), basis.mode_vectors
        self.mass_kept = _mass_kept(basis)  # M Phi_kept, so projections need no sparse product
        self.loads = np.asarray(loads, dtype=float).reshape(self.kept.shape[0], -1)
        self.buf = np.zeros((self.kept.shape[0], 16 * self.loads.shape[1]))
        self.mbuf = np.zeros_like(self.buf)  # M times each column of buf
        self.count = 0  # columns of buf in use
        self.ends = [0]  # columns in use after each Krylov step
        self.block = None  # the next step's vectors, before orthogonalisation
        self.exhausted = False

    def extend(self, k: int) -> None:
        """Grow the space to k Krylov steps (or until it is exhausted), under the basis
        builds' BLAS thread limit (``tailbeam.plate.blas``)."""
        with limited():
            self._extend(k)

    def _extend(self, k: int) -> None:
        solve = self.model.solver().solve
        if self.block is None:
            self.block = solve(self.loads)
        while len(self.ends) - 1 < k and not self.exhausted:
            fresh = [self._add(u) for u in self.block.T]
            fresh = [c for c in fresh if c is not None]
            self.ends.append(self.count)
            if not fresh:
                self.exhausted = True
                break
            self.block = solve(self.mbuf[:, fresh])

    def _add(self, u):
        """M-orthogonalise u against the kept modes and the space (classical Gram-Schmidt,
        twice: Kahan-Parlett) and append it; its column, or None when it breaks down."""
        M = self.model.mass
        start = np.sqrt(u @ (M @ u))
        V, MV = self.buf[:, : self.count], self.mbuf[:, : self.count]
        for _ in range(2):
            u = u - self.kept @ (self.mass_kept.T @ u) - V @ (MV.T @ u)
        Mu = M @ u
        norm = np.sqrt(u @ Mu)
        if norm <= BREAKDOWN * start:
            return None
        if self.count == self.buf.shape[1]:  # room doubles: copies stay O(final size)
            self.buf = np.hstack([self.buf, np.zeros_like(self.buf)])
            self.mbuf = np.hstack([self.mbuf, np.zeros_like(self.mbuf)])
        self.buf[:, self.count], self.mbuf[:, self.count] = u / norm, Mu / norm
        self.count += 1
        return self.count - 1

    def modes(self, k: int):
        """(omega rad/s ascending, Z): Rayleigh-Ritz on (K, M) over the first k steps."""
        self.extend(k)
        count = self.ends[min(k, len(self.ends) - 1)]
        if count == 0:  # the loads move no truncated mode
            return np.zeros(0), self.buf[:, :0]
        V = self.buf[:, :count]
        with limited():
            theta, Y = eigh(V.T @ (self.model.stiffness @ V), V.T @ self.mbuf[:, :count])
            return np.sqrt(theta), V @ Y


_MASS_KEPT: dict = {}  # id(Phi_kept) -> (Phi_kept, M Phi_kept), the last KRYLOV_MEMO


def _mass_kept(basis) -> np.ndarray:
    """M Phi_kept (n_dofs, modes) of ``basis``, computed once per set of kept modes (a sweep's
    cases share the bases read from the cache, tailbeam.plate.fe.modes._from_cache)."""
    kept = basis.mode_vectors
    return _remember(_MASS_KEPT, id(kept), kept, lambda: basis.fe_model().mass @ kept)


def with_ritz_tail(basis, points, contact_radius: float = 0.0, k: int = 32) -> ModalBasis:
    """``basis`` plus k load-dependent Ritz pseudo-modes per load point (``ritz_tail_modes``).

    points: (p, 2) m, where the loads act (the contact points, known in advance);
    contact_radius: m, the load is 1 N spread over a disc of this radius (0: a point load;
    use ``tailbeam.physics.contact_patch.load_radius`` as the solver does), one for every point or
    a sequence of p, one per point (balls of different sizes). The pseudo-modes have
    their true shapes (seen at sensors and other points), and the residual compliance of the
    returned basis (static minus every mode it holds) is ~0 at the points. Raises InputError
    for bad input, WorkLimitError if k x points exceeds MAX_RITZ_VECTORS.
    """
    check_fe_basis(basis)
    _check_count("k", k, 1)
    pts = check_points(basis.plate, points)
    radii = _radii(contact_radius, len(pts))
    if k * len(pts) > MAX_RITZ_VECTORS:
        raise WorkLimitError(
            f"{k} Ritz vectors x {len(pts)} points > {MAX_RITZ_VECTORS}; lower k or the points"
        )
    model = basis.fe_model()
    loads = np.column_stack([model.load_vector(p, r) for p, r in zip(pts, radii, strict=True)])
    omega, Z = ritz_tail_modes(basis, loads, int(k))
    kept, seen = basis.mode_vectors, {}

    def deflection_at(at):
        # one mesh search for the kept and the Ritz modes, memoised: the solver asks again
        # for the same contact or sensor points (each search ~10 ms on the 23x23 mesh)
        at = np.atleast_2d(np.asarray(at, dtype=float))
        key = at.tobytes()
        if key not in seen:
            if len(seen) >= DEFLECTION_MEMO:
                seen.pop(next(iter(seen)))
            op = model.deflection_operator(at)
            seen[key] = np.column_stack([op @ kept, op @ Z])
        return seen[key].copy()

    info = dict(basis.info, ritz_tail={"k": int(k), "points": pts.tolist(), "added": len(omega)})
    return ModalBasis(
        basis.plate,
        np.append(basis.frequencies_hz, omega / (2.0 * np.pi)),
        deflection_at,
        basis.theory,
        basis.boundary,
        basis.static_compliance_at,
        basis.static_deflection_at,
        info,
    )


def _radii(contact_radius, n: int) -> list:
    """n load radii (m) from one radius or a sequence of n, else InputError."""
    radii = np.asarray(contact_radius, dtype=float).ravel()
    if radii.size not in (1, n):
        raise InputError("contact_radius", f"must be one radius or {n}, one per point")
    return [require_nonnegative("contact_radius", float(r)) for r in np.resize(radii, n)]


def check_fe_basis(
    basis, field="basis", rule="needs the FE mode vectors and model (use compute_modes)"
):
    """InputError naming ``field`` unless ``basis`` carries its FE mode vectors and model."""
    if getattr(basis, "mode_vectors", None) is None or not hasattr(basis, "fe_model"):
        raise InputError(field, rule)


def _check_count(field, value, least):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < least:
        raise InputError(field, f"must be a whole number >= {least}, got {value!r}")


def half_sine_response(omega, fz, duration: float, peak_force: float, t) -> np.ndarray:
    """Deflection (m) under the load of pseudo-modes (omega (m,) rad/s, f.z (m,)) at rest,
    driven by F = peak_force sin(pi t / duration) N at times t (s) within the contact:
    q_j = F_peak (sin W t - (W / omega_j) sin omega_j t) / (omega_j^2 - W^2), W = pi/duration
    (closed form; the tail lies far above W)."""
    w = np.pi / duration
    t = np.asarray(t, dtype=float)[:, None]
    q = peak_force * (np.sin(w * t) - (w / omega) * np.sin(omega * t)) / (omega**2 - w**2)
    return q @ (fz**2)


def choose_ritz_k(basis, point, contact_radius, duration, peak_force, max_penetration,
                  tol: float = 1e-5, k_max: int = 512):  # fmt: skip
    """The number of Ritz pseudo-modes for one contact, a posteriori: k doubles from K_START
    until the tail model's deflection under a half-sine force of ``duration`` s and
    ``peak_force`` N changes from k to 2k by less than ``tol`` x ``max_penetration`` m (RMS over
    the contact). Measured on the cases of docs/fe-convergence.md ("Many-node tails"): the
    contact error with k pseudo-modes is then below 0.88 x tol, plus the time-step error.
    Returns (k, that relative change). WorkLimitError if 2k would exceed ``k_max``."""
    check_fe_basis(basis)
    for name, value in (("duration", duration), ("peak_force", peak_force),
                        ("max_penetration", max_penetration), ("tol", tol)):  # fmt: skip
        require_positive(name, value)
    _check_count("k_max", k_max, 2 * K_START)
    if k_max > MAX_RITZ_VECTORS:
        raise InputError("k_max", f"must be <= {MAX_RITZ_VECTORS}, got {k_max!r}")
    model = basis.fe_model()
    load = model.load_vector(check_points(basis.plate, point)[0], contact_radius)[:, None]
    t = np.linspace(0.0, duration, 4001)

    krylov = krylov_tail(basis, load)  # grown once: k, 2k, 4k ... share its first vectors

    def response(k):
        omega, Z = krylov.modes(k)
        return half_sine_response(omega, (load.T @ Z)[0], duration, peak_force, t)

    k, w_k = K_START, response(K_START)
    while 2 * k <= k_max:
        w_2k = response(2 * k)
        change = float(np.sqrt(np.mean((w_2k - w_k) ** 2))) / max_penetration
        if change < tol:
            return k, change
        k, w_k = 2 * k, w_2k
    raise WorkLimitError(
        f"the Ritz tail has not converged to tol={tol:g} with k_max={k_max} modes; raise tol "
        "or k_max"
    )
