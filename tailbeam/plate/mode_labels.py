"""(m, n) labels of computed plate mode shapes, for figures and tables.

Two definitions, chosen by the boundary code:

* SSSS: the closed-form shapes sin(m pi (x + a/2) / a) sin(n pi (y + b/2) / b) are complete and
  orthogonal on the simply supported plate, so a computed shape is projected on them and labelled
  with the (m, n) that carries the largest share of its mean square (the share is reported:
  modes of a square plate that share a frequency, e.g. (1, 2) and (2, 1), are mixtures of both).
* any other boundary: m (n) = 1 + the number of nodal lines crossed along a line parallel to x
  (y), the most common count over the lines where the shape is large. It is a count of
  half-waves; it is not the closed-form index of a clamped or free plate (a free edge's
  beam-like modes have no simple sine), and it is ambiguous for mixed shapes with diagonal
  nodal lines.
"""

from dataclasses import dataclass

import numpy as np

MAX_INDEX = 20  # largest m, n tried in the SSSS projection
NODE_THRESHOLD = 0.02  # samples below this fraction of max |w| are treated as nodes
LINE_THRESHOLD = 0.3  # lines whose RMS is below this fraction of the largest are skipped
MIXED_SHARE = 0.9  # below this share, the SSSS label names the two largest components


@dataclass(frozen=True)
class ModeLabel:
    """m, n (half-waves along x and y), method ("SSSS projection" or "nodal count"), share of
    the shape's mean square in (m, n) (projection only, else nan), the second component
    (m2, n2, share2) when the shape is a mixture (projection only, else None)."""

    m: int
    n: int
    method: str
    share: float = float("nan")
    second: tuple | None = None

    def text(self) -> str:
        if self.method == "nodal count":
            return f"nodal ({self.m}, {self.n})"
        if self.second is None:
            return f"({self.m}, {self.n})"
        m2, n2, s2 = self.second
        return f"({self.m}, {self.n}) {self.share:.0%} + ({m2}, {n2}) {s2:.0%}"


def _trapezoid_weights(x) -> np.ndarray:
    """Weights of the trapezoidal rule on the increasing samples ``x``."""
    dx = np.diff(np.asarray(x, dtype=float))
    return 0.5 * (np.concatenate([dx, [0.0]]) + np.concatenate([[0.0], dx]))


def sine_shares(z, x, y, size_x: float, size_y: float) -> np.ndarray:
    """shares[m-1, n-1]: fraction of the mean square of the sampled shape ``z[j, i]`` (at
    x[i], y[j], plate centred at 0) carried by the SSSS sine (m, n), m, n <= MAX_INDEX."""
    k = np.arange(1, MAX_INDEX + 1)
    sx = np.sin(np.outer(k, (np.asarray(x) + 0.5 * size_x)) * np.pi / size_x)  # (M, nx)
    sy = np.sin(np.outer(k, (np.asarray(y) + 0.5 * size_y)) * np.pi / size_y)  # (N, ny)
    wx, wy = _trapezoid_weights(x), _trapezoid_weights(y)
    zw = np.asarray(z) * np.outer(wy, wx)
    coef = sy @ zw @ sx.T  # (N, M): integral of z sin_m sin_n
    norm = 0.25 * size_x * size_y  # integral of sin_m^2 sin_n^2
    energy = np.sum(np.asarray(z) ** 2 * np.outer(wy, wx))
    return (coef.T**2 / norm) / energy if energy > 0 else np.zeros((MAX_INDEX, MAX_INDEX))


def projection_label(z, x, y, size_x: float, size_y: float) -> ModeLabel:
    """Label by the SSSS sine carrying the largest share (see module docstring)."""
    shares = sine_shares(z, x, y, size_x, size_y)
    order = np.argsort(shares, axis=None)[::-1]
    (m1, n1), (m2, n2) = (np.unravel_index(i, shares.shape) for i in order[:2])
    share1, share2 = float(shares[m1, n1]), float(shares[m2, n2])
    second = (int(m2) + 1, int(n2) + 1, share2) if share1 < MIXED_SHARE else None
    return ModeLabel(int(m1) + 1, int(n1) + 1, "SSSS projection", share1, second)


def _half_waves(lines) -> int:
    """1 + the most common number of sign changes along the rows of ``lines``, over the rows
    whose RMS is at least LINE_THRESHOLD of the largest; near-zero samples are skipped."""
    lines = np.asarray(lines, dtype=float)
    top = np.abs(lines).max()
    rms = np.sqrt(np.mean(lines**2, axis=1))
    counts = []
    for row in lines[rms >= LINE_THRESHOLD * rms.max()]:
        s = np.sign(row[np.abs(row) > NODE_THRESHOLD * top])
        counts.append(int(np.count_nonzero(s[1:] != s[:-1])))
    return 1 + int(np.bincount(counts).argmax()) if counts else 1


def nodal_label(z) -> ModeLabel:
    """Half-wave counts of ``z[j, i]`` (rows along x, columns along y)."""
    z = np.asarray(z, dtype=float)
    return ModeLabel(_half_waves(z), _half_waves(z.T), "nodal count")


def label_modes(boundary: str, z_stack, x, y, size_x: float, size_y: float) -> list:
    """ModeLabel of every shape z_stack[k] (sampled at x[i], y[j] as z[j, i])."""
    if boundary == "SSSS":
        return [projection_label(z, x, y, size_x, size_y) for z in z_stack]
    return [nodal_label(z) for z in z_stack]
