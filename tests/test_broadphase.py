"""Broad phase (tailbeam.solvers.stream.driver.broadphase): the cell grid against brute force, and
against the actual closest approach of balls moving within their speed bounds (never a missed
pair)."""

import numpy as np
import pytest

from tailbeam.errors import InputError
from tailbeam.solvers.stream.driver.broadphase import candidate_pairs, candidate_pairs_brute_force


def _scene(rng, n, side, r_max=0.04):
    x = rng.uniform(0.0, side, (n, 3))
    r = rng.uniform(0.25 * r_max, r_max, n)
    s = rng.uniform(0.0, 6.0, n) * (rng.random(n) < 0.8)  # some balls at rest
    return x, r, s


@pytest.mark.parametrize("seed", range(8))
def test_grid_equals_brute_force_on_random_scenes(seed):
    rng = np.random.default_rng(seed)
    n = int(rng.integers(2, 1500))
    side = float(rng.choice([0.05, 0.3, 1.0, 20.0]))  # from one crowded cell to sparse
    x, r, s = _scene(rng, n, side)
    horizon = float(rng.choice([0.0, 1e-3, 1e-2]))
    grid = candidate_pairs(x, r, s, horizon, margin=1e-4)
    brute = candidate_pairs_brute_force(x, r, s, horizon, margin=1e-4, block=257)
    assert np.array_equal(grid, brute)


def test_touching_and_boundary_pairs():
    """Balls exactly touching, and a lattice whose neighbours sit exactly at the limit."""
    x = np.array([[0.0, 0.0, 0.0], [0.02, 0.0, 0.0], [0.5, 0.5, 0.5]])
    pairs = candidate_pairs(x, [0.01, 0.01, 0.01], 0.0, 0.0)
    assert pairs.tolist() == [[0, 1]]
    g = np.arange(6) * 0.5  # exact binary fractions: neighbours touch exactly
    lattice = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    grid = candidate_pairs(lattice, np.full(len(lattice), 0.25), 0.0, 0.0)
    assert np.array_equal(grid, candidate_pairs_brute_force(lattice, 0.25, 0.0, 0.0))
    assert len(grid) == 3 * 6 * 6 * 5  # every lattice neighbour along x, y, z


def test_no_missed_contact_for_balls_moving_within_their_bounds():
    """Straight motion at speeds <= the bounds over the horizon: the exact closest approach
    of every pair (relative motion is linear) is computed; every pair that touches is a
    candidate."""
    rng = np.random.default_rng(42)
    n, horizon = 1200, 0.02
    x, r, s = _scene(rng, n, 0.6)
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1)[:, None]
    v = direction * (s * rng.uniform(0.0, 1.0, n))[:, None]
    candidates = {tuple(p) for p in candidate_pairs(x, r, s, horizon)}
    i, j = np.triu_indices(n, 1)
    d0, w = x[i] - x[j], v[i] - v[j]
    t_min = np.clip(
        -np.einsum("pk,pk->p", d0, w) / np.maximum(np.einsum("pk,pk->p", w, w), 1e-300),
        0.0,
        horizon,
    )
    closest = np.linalg.norm(d0 + w * t_min[:, None], axis=1)
    touching = closest <= r[i] + r[j]
    assert touching.sum() > 10  # the scene does have contacts within the horizon
    missed = [
        (a, b) for a, b in zip(i[touching], j[touching], strict=True) if (a, b) not in candidates
    ]
    assert missed == []


def test_bad_input_names_the_field():
    with pytest.raises(InputError, match="speed_bounds"):
        candidate_pairs(np.zeros((2, 3)), [0.01, 0.01], [-1.0, 0.0], 1e-3)
    with pytest.raises(InputError, match="horizon"):
        candidate_pairs(np.zeros((2, 3)), [0.01, 0.01], 0.0, float("nan"))
    assert candidate_pairs(np.zeros((1, 3)), [0.01], 0.0, 1.0).shape == (0, 2)
