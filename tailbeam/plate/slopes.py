"""Slopes of a field over the flat plate's mid-plane by central differences.

The modal bases give the deflection w at points, not its gradient. Where a quantity needs
grad w (the in-plane motion -zeta grad w of a point zeta above the mid-plane: friction's
lever on the top surface, a sensor's in-plane axis), it is taken here, by central
differences of step ``GRADIENT_STEP``: relative error ~(k h)^2 / 6 of the slope for a mode
of wavenumber k (< 1e-7 below k = 100 /m), round-off ~eps |w| / (h |grad w|).
"""

import numpy as np

GRADIENT_STEP = 1e-5  # m


def values_and_slopes(evaluate, points, half_size=None):
    """A field and its gradient at points of the mid-plane.

    Parameters
    ----------
    evaluate : callable
        ``evaluate(xy)`` -> (n, k): the field (k components) at points xy (n, 2) m.
    points : array_like, (p, 2)
        Points, m.
    half_size : array_like (2,), optional
        Half the plate's sides, m: the stencil is kept on the plate (one-sided at an edge).
        None: centred everywhere.

    Returns
    -------
    values : (p, k) the field at the points.
    slopes : (p, k, 2) its derivatives along x and y (field unit per m).
    """
    xy = np.reshape(np.asarray(points, dtype=float), (-1, 2))
    offsets = GRADIENT_STEP * np.array([[0.0, 0.0], [1, 0], [-1, 0], [0, 1], [0, -1]])
    stencil = xy[None, :, :] + offsets[:, None, :]  # (5, p, 2)
    if half_size is not None:
        half = np.asarray(half_size, dtype=float)
        stencil = np.clip(stencil, -half, half)
    values = np.asarray(evaluate(stencil.reshape(-1, 2)), dtype=float)
    values = values.reshape(5, xy.shape[0], -1)
    dx = (stencil[1, :, 0] - stencil[2, :, 0])[:, None]
    dy = (stencil[3, :, 1] - stencil[4, :, 1])[:, None]
    slopes = np.stack([(values[1] - values[2]) / dx, (values[3] - values[4]) / dy], axis=-1)
    return values[0], slopes
