"""What an active set integrates: its balls, pairs and their laws, the plate and its modes.

``Model`` checks the inputs of ``set.ActiveSet`` and holds them as the arrays the compiled
kernel takes (``arrays``: the ``model`` tuple of ``kernel.advance``). Most of them stay fixed
for the life of the set; the caller changes a ball's settle energy or whether it is still
integrated (``alive``), and on the modal plate a plate pair's mode shapes and residual
compliance before it touches (``set_phi``, ``set_compliance``).
"""

import math

import numpy as np

from tailbeam.errors import InputError
from tailbeam.physics.contact_law import LAW_COLUMNS, law_table
from tailbeam.solvers.stream.active.compiled.friction import F_COLUMNS, F_GRAD
from tailbeam.solvers.stream.active.compiled.pairs import FIXED, INTEGRATED, L_CRES


class Model:
    """The balls, pairs and modes of an active set, in the order the kernel takes them.

    Parameters
    ----------
    n : int
        Number of balls.
    mass, radius : array_like, shape (n,)
        Masses (kg) and radii (m) of the balls.
    pairs : array_like, shape (P, 2)
        Ball indices of the watched pairs (j = -1: the plate).
    laws : sequence of ImpactLaw or ndarray, shape (P, LAW_COLUMNS)
        The pairs' IMPACT laws, or their ``tailbeam.physics.contact_law.law_table``.
    gravity : array_like, shape (3,)
        Gravity in the plate frame (m/s^2).
    half_sizes : array_like, shape (2,)
        Half the plate's sides a/2, b/2 (m).
    settle_energy : array_like, shape (n,) or None
        Energy (J) below which a ball's plate contact settles (0 = never; None: 0 for all).
    compliance : array_like, shape (P,) or None
        Residual compliance (m/N) of each plate pair (entries of ball-ball pairs ignored;
        None: 0).
    modes : ModalBlock
        The modal plate's modes (``modal_block``; none on the rigid plate).
    friction : array_like, shape (P, F_COLUMNS) or (P, F_GRAD + 2 m), optional
        The pairs' friction table (``compiled.friction``; on the modal plate with the levers
        and shape gradients); None: frictionless.

    Attributes
    ----------
    mass, radius : ndarray, shape (n,)
        kg, m.
    g : ndarray, shape (3,)
        Gravity (m/s^2).
    half : ndarray, shape (2,)
        Half sizes of the plate (m).
    pi, pj : ndarray of int64, shape (P,)
        The pairs' balls (pj = -1: the plate).
    law : ndarray, shape (P, L_CRES + 1)
        The laws (k, e, c, d, clamp) and, in column ``pairs.L_CRES``, the residual compliance
        (m/N; 0 for ball-ball pairs).
    rsum : ndarray, shape (P,)
        Sum of the pair's radii (m; the ball's alone for a plate pair).
    settle_energy : ndarray, shape (n,)
        J, in/out (the caller puts a ball at rest or wakes it).
    alive : ndarray of int8, shape (n,)
        Each ball's code (``pairs``): INTEGRATED, GONE (after a leave) or FIXED (an obstacle
        held where it is, ``fix``).
    omega, zeta, f_dead : ndarray, shape (m,)
        Modal frequencies (rad/s), damping ratios, constant modal forces (N/sqrt(kg)).
    phi : ndarray, shape (P, m)
        Mode shapes (1/sqrt(kg)) at each plate pair's contact point.
    fric : ndarray, shape (P, F_COLUMNS) or (P, F_GRAD + 2 m) or (P, 0)
        The friction table (modal plate: with the levers and shape gradients; no columns:
        frictionless).
    """

    def __init__(self, n, mass, radius, pairs, laws, gravity, half_sizes, settle_energy,
                 compliance, modes, friction=None):  # fmt: skip
        self.mass = np.asarray(mass, dtype=float).reshape(n).copy()
        self.radius = np.asarray(radius, dtype=float).reshape(n).copy()
        pairs = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
        self.pi, self.pj = pairs[:, 0].copy(), pairs[:, 1].copy()
        if not isinstance(laws, np.ndarray):
            laws = law_table(laws)
        self.law = _with_compliance(laws, self.pj, compliance)
        _check_pairs(n, self.pi, self.pj)
        _check_positive("mass", self.mass)
        _check_positive("radius", self.radius)
        self.rsum = self.radius[self.pi] + np.where(self.pj >= 0, self.radius[self.pj], 0.0)
        self.g = np.asarray(gravity, dtype=float).reshape(3).copy()
        self.half = np.asarray(half_sizes, dtype=float).reshape(2).copy()
        _check_positive("half_sizes", self.half)
        settle = np.zeros(n) if settle_energy is None else settle_energy
        self.settle_energy = np.asarray(settle, dtype=float).reshape(n).copy()
        if not np.all(self.settle_energy >= 0.0):
            raise InputError("settle_energy", "must be >= 0 J for every ball (0 = never)")
        self.alive = np.full(n, INTEGRATED, dtype=np.int8)
        self.omega, self.zeta = modes.omega, modes.zeta
        self.phi, self.f_dead = modes.phi, modes.f_dead
        self.fric = _friction_table(friction, len(self.pi), self.omega.shape[0])

    @property
    def friction(self) -> bool:
        """Whether the set has friction (and the balls' angular velocities in its state)."""
        return self.fric.shape[1] > 0

    def arrays(self) -> tuple:
        """The ``model`` tuple of ``kernel.advance`` (the arrays themselves, not copies)."""
        return (self.mass, self.radius, self.g, self.half, self.pi, self.pj, self.law,
                self.rsum, self.settle_energy, self.alive, self.omega, self.zeta, self.phi,
                self.f_dead, self.fric)  # fmt: skip

    def fix(self, b: int) -> None:
        """Ball b is a FIXED obstacle from now: held where it is (its velocity and angular
        velocity must be 0 in the state), feeling no force, its pairs acting on their other
        ball only."""
        self.alive[b] = FIXED

    def set_phi(self, p: int, shape) -> None:
        """Mode shapes (m,) 1/sqrt(kg) at plate pair p's new contact point (before it touches)."""
        self.phi[p] = np.asarray(shape, dtype=float).reshape(self.phi.shape[1])

    def set_compliance(self, p: int, compliance: float) -> None:
        """Residual compliance (m/N) at plate pair p's new contact point (before it touches)."""
        value = float(compliance)
        if not (math.isfinite(value) and value >= 0.0):
            raise InputError("compliance", f"must be finite and >= 0 m/N, got {value!r}")
        self.law[p, L_CRES] = value

    def set_gradients(self, p: int, grad) -> None:
        """Gradients (m, 2) 1/(m sqrt(kg)) of the mode shapes at plate pair p's new contact
        point (before it touches), into a modal friction table."""
        if self.fric.shape[1] > F_GRAD:
            m = (self.fric.shape[1] - F_GRAD) // 2
            grad = np.asarray(grad, dtype=float).reshape(-1, 2)
            self.fric[p, F_GRAD:] = 0.0
            self.fric[p, F_GRAD : F_GRAD + len(grad)] = grad[:, 0]
            self.fric[p, F_GRAD + m : F_GRAD + m + len(grad)] = grad[:, 1]


def _with_compliance(laws, pj, compliance) -> np.ndarray:
    """(P, L_CRES + 1) law table: a (P, LAW_COLUMNS) ``law_table`` and the residual
    compliance of each plate pair (m/N; 0 for ball-ball pairs and when ``compliance`` is None)."""
    laws = np.asarray(laws, dtype=float)
    laws = laws if laws.ndim == 2 else laws.reshape(-1, LAW_COLUMNS)
    if laws.shape[0] != len(pj):
        raise InputError("laws", f"one law per pair: got {len(laws)} laws for {len(pj)} pairs")
    laws = laws[:, :LAW_COLUMNS]
    cres = np.zeros(len(pj)) if compliance is None else np.asarray(compliance, dtype=float)
    if cres.shape != (len(pj),) or not np.all(np.isfinite(cres)) or np.any(cres < 0.0):
        raise InputError("compliance", f"must be {len(pj)} finite values >= 0 m/N (one per pair)")
    return np.ascontiguousarray(np.column_stack([laws, np.where(pj < 0, cres, 0.0)]))


def _friction_table(friction, n_pairs, n_modes) -> np.ndarray:
    """(P, F_COLUMNS) friction table (``compiled.friction``), on the modal plate possibly
    (P, F_GRAD + 2 n_modes) (the levers and shape gradients), or (P, 0) without friction."""
    if friction is None:
        return np.zeros((n_pairs, 0))
    table = np.asarray(friction, dtype=float)
    width = table.shape[-1] if table.ndim == 2 else F_COLUMNS
    if width not in (F_COLUMNS, F_GRAD + 2 * n_modes):
        raise InputError(
            "friction", f"{F_COLUMNS} columns, or {F_GRAD + 2 * n_modes} with the modal plate's "
            f"{n_modes} modes; got {width}"
        )  # fmt: skip
    table = np.ascontiguousarray(table.reshape(-1, width))
    if table.shape[0] != n_pairs:
        raise InputError("friction", f"one row per pair: got {table.shape[0]} for {n_pairs}")
    return table


def _check_positive(name, values):
    if not np.all(np.isfinite(values)) or not np.all(values > 0.0):
        raise InputError(name, f"must be finite and > 0, got {values.tolist()!r}")


def _check_pairs(n, pi, pj):
    """InputError unless every pair joins two different balls of the n, or a ball and the
    plate."""
    if np.any(pi < 0) or np.any(pi >= n) or np.any(pj >= n) or np.any(pj < -1):
        raise InputError("pairs", f"ball indices must lie in [0, {n}) (j = -1: the plate)")
    if np.any(pi == pj):
        raise InputError("pairs", "a ball cannot pair with itself")
