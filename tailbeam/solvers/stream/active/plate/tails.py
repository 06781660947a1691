"""The contact tails of the active set's plate pairs (tailbeam.plate.contact_tail),
by pair key: their oscillators' states across rebuilds of the set, their columns in the built
modal block, and the energy of those dropped.

A tail's oscillators are modes of the set's modal block after the plate's own, with shapes
only in their pair's row of phi and no dead loads, so the compiled kernel, its events and its
energy ledger take them as any other modes. ``ActiveMembers`` decides when a pair gets or
loses its tail (it syncs and rebuilds the set around these calls).
"""

import numpy as np


class Tails:
    """Tails by plate pair key: ``TailModes`` and the state (eta, eta') of its oscillators."""

    def __init__(self):
        self.states = {}  # key -> [TailModes, eta, eta']
        self.cols = {}  # key -> the tail's columns in the last built modal block
        self.dropped = 0.0  # J: held by the tails when they were dropped

    def __contains__(self, key) -> bool:
        return key in self.states

    def modes(self, key):
        """The ``TailModes`` of pair ``key``."""
        return self.states[key][0]

    def add(self, key, modes) -> None:
        """Pair ``key`` gets the oscillators ``modes`` (a ``TailModes``), at rest."""
        k = len(modes.nu)
        self.states[key] = [modes, np.zeros(k), np.zeros(k)]

    def save(self, q, qd) -> None:
        """The oscillators' states from the built set's modal state (q, q')."""
        for key, cols in self.cols.items():
            if key in self.states:
                self.states[key][1:] = [q[cols].copy(), qd[cols].copy()]

    def drop(self, key) -> None:
        """Drop pair ``key``'s oscillators (states saved); their energy to ``dropped``."""
        self.dropped += self._energy(key)
        del self.states[key]

    def energy(self) -> float:
        """Energy (J) held by the tails now (states saved)."""
        return sum(self._energy(key) for key in self.states)

    def _energy(self, key) -> float:
        modes, eta, etad = self.states[key]
        return 0.5 * float(np.sum(etad**2 + (modes.nu * eta) ** 2))

    def block(self, plate, phi, row_of) -> dict:
        """The modal block of a set: ``plate``'s modes (a StreamPlate), then each tail's
        oscillators; phi (P, m) the plate's shapes at the pairs, ``row_of(key)`` a tail's pair
        row. Keys omega, zeta, q, qd, phi, f_dead as ``ActiveSet`` takes them."""
        parts = [(plate.omega, plate.zeta, plate.q, plate.qd)]
        rows, self.cols = [], {}
        n = plate.n_modes
        for key, (modes, eta, etad) in self.states.items():
            k = len(modes.nu)
            self.cols[key] = slice(n, n + k)
            rows.append((row_of(key), n, modes.b))
            parts.append((modes.nu, modes.zeta, eta, etad))
            n += k
        full = np.zeros((phi.shape[0], n))
        full[:, : plate.n_modes] = phi
        for p, start, b in rows:
            full[p, start : start + len(b)] = b
        omega, zeta, q, qd = (np.concatenate(c) for c in zip(*parts, strict=True))
        f_dead = np.concatenate([plate.f_dead, np.zeros(n - plate.n_modes)])
        return dict(omega=omega, zeta=zeta, q=q, qd=qd, phi=full, f_dead=f_dead)
