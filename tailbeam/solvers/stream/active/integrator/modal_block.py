"""The optional modal-plate block of the active-set integrator: its inputs, checked.

m mass-normalised plate modes (unit modal mass): q'' + 2 zeta omega q' + omega^2 q = f, q in
m sqrt(kg), mode shapes phi in 1/sqrt(kg) (deflection phi . q in m), modal force f in
N/sqrt(kg). ``ModalBlock.build`` turns the optional arguments of ``ActiveSet`` into arrays
(m = 0: the rigid plate) and rejects bad input with an ``InputError`` naming the argument.
"""

from dataclasses import dataclass

import numpy as np

from tailbeam.errors import InputError


@dataclass(frozen=True)
class ModalBlock:
    """omega (m,) rad/s, zeta (m,), q, qd (m,), phi (P, m), f_dead (m,); m may be 0."""

    omega: np.ndarray
    zeta: np.ndarray
    q: np.ndarray
    qd: np.ndarray
    phi: np.ndarray
    f_dead: np.ndarray

    @classmethod
    def build(cls, n_pairs, omega=None, zeta=None, q=None, qd=None, phi=None, f_dead=None):
        """Arrays from the optional inputs (all absent: no modes); see the module docstring."""
        if omega is None:
            given = [k for k, v in dict(zeta=zeta, q=q, qd=qd, phi=phi, f_dead=f_dead).items()
                     if v is not None]  # fmt: skip
            if given:
                raise InputError(given[0], "needs omega (the modal plate's frequencies)")
            omega = np.zeros(0)
        omega = _vector("omega", omega, None)
        m = omega.shape[0]
        if not np.all(omega > 0.0):
            raise InputError("omega", "must be > 0 rad/s for every mode (no rigid-body modes)")
        zeta = _vector("zeta", np.zeros(m) if zeta is None else zeta, m)
        if not np.all((zeta >= 0.0) & (zeta < 1.0)):
            raise InputError("zeta", "damping ratios must lie in [0, 1)")
        phi = np.zeros((n_pairs, m)) if phi is None else np.asarray(phi, dtype=float)
        if phi.shape != (n_pairs, m) or not np.all(np.isfinite(phi)):
            raise InputError(
                "phi", f"must be finite with shape (pairs, modes) = ({n_pairs}, {m}), "
                f"got {phi.shape}"
            )  # fmt: skip
        return cls(
            omega, zeta,
            _vector("q", np.zeros(m) if q is None else q, m),
            _vector("qd", np.zeros(m) if qd is None else qd, m),
            np.ascontiguousarray(phi).copy(),
            _vector("f_dead", np.zeros(m) if f_dead is None else f_dead, m),
        )  # fmt: skip


def _vector(name, values, m):
    """A finite float vector of length m (any length if m is None), copied."""
    v = np.array(values, dtype=float).ravel()
    if (m is not None and v.shape[0] != m) or not np.all(np.isfinite(v)):
        size = "" if m is None else f" of length {m} (one per mode)"
        raise InputError(name, f"must be a finite vector{size}, got shape {np.shape(values)}")
    return v
