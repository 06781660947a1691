"""Mode shapes under the balls of the active set (modal plate), cached by ball.

Evaluating the plate's mode shapes at a point costs a basis evaluation; a ball that has
moved less than SHAPE_REUSE since its shapes were computed reuses them (with the point they
were computed at), so the shapes of a ball sliding or bouncing in place are computed once.
"""

import numpy as np

SHAPE_REUSE = 2.5e-4  # m: mode shapes computed within this distance are reused


class ShapeCache:
    """The mode shapes last computed under each ball, and the point they were computed at.

    Parameters
    ----------
    plate : StreamPlate
        The modal plate (``shapes(xy)``: (k, m) mode shapes in 1/sqrt(kg) at k points).
    """

    def __init__(self, plate):
        self.plate = plate
        self.rows = {}  # ball -> (xy (2,) m, mode shapes (m,) 1/sqrt(kg))

    def shapes(self, balls, xy) -> tuple[np.ndarray, np.ndarray]:
        """Mode shapes under ``balls`` at ``xy``.

        Parameters
        ----------
        balls : sequence of int
            Ball numbers.
        xy : array_like, shape (len(balls), 2)
            Their positions (m).

        Returns
        -------
        shapes : ndarray, shape (len(balls), m)
            Mode shapes (1/sqrt(kg)): each ball's cached row unless it moved more than
            SHAPE_REUSE since it was computed (one batched evaluation for the rest).
        points : ndarray, shape (len(balls), 2)
            The points (m) the rows were computed at.
        """
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        out = np.empty((len(balls), self.plate.n_modes))
        points = xy.copy()
        todo = []
        for k, i in enumerate(balls):
            cached = self.rows.get(i)
            if cached is not None and np.hypot(*(cached[0] - xy[k])) <= SHAPE_REUSE:
                points[k], out[k] = cached
            else:
                todo.append(k)
        if todo:
            fresh = self.plate.shapes(xy[todo])
            for k, row in zip(todo, fresh, strict=True):
                out[k] = row
                self.rows[balls[k]] = (xy[k].copy(), row)
        return out, points
