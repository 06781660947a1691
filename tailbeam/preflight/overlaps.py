"""Bodies that overlap at release are refused before any work.

- Two ``[[balls]]`` overlap when their centres, as floating-point numbers, are closer than
  the sum of their radii: touching balls are valid, overlapping ones are not, even by the
  rounding of written decimals (0.116 and 0.176 for two 30 mm balls are 1.4e-17 m too close;
  the message then says so, ``TOUCH_TOLERANCE``). The solvers start every contact from a gap:
  the stream solver does not see a ball-ball contact that already exists at release (two
  30 mm balls overlapping by 1e-17 m and approaching at 0.2 m/s pass through each other),
  and the single-ball solvers refuse a ball below the plate's surface, so a release state
  inside another body has no correct run.
- A stream particle overlaps a ball when, at its release time, it overlaps that ball on the
  ball's undisturbed path: free flight (gravity in the plate frame) from its initial state
  until it first touches the plate, or, for a ball set down on the plate without a normal
  velocity, sliding (or resting) on the frictionless plate; in both cases until its centre
  passes an edge (it leaves the plate) or the run ends. After a ball's first plate contact
  its path is known only to the solver, which holds back a particle that would overlap it
  (docs/scene-files.md, ``particles.csv``).
- Ball-plate: a ball's centre must be at least its radius above z = 0 (touching is valid;
  ``tailbeam.physics.bodies.check_ball_above_plate``, as every solver checks it).

Cost: a k-d tree (scipy.spatial.cKDTree) over the balls' centres, and one over the
particles' release events (position and time) queried along each ball's path: O(n log n)
for n bodies, plus the pairs found near each other in space and time.
"""

import math

import numpy as np

from tailbeam.errors import InputError

TOUCH_TOLERANCE = 1e-9  # of r_i + r_j: an overlap this small is the rounding of decimals
MAX_SAMPLES = 100_000  # points per ball path (a longer path is sampled more coarsely)
TIME_SCALE = 1.0  # m/s: release times become a fourth coordinate c t of the particle tree


def _f(x: float) -> str:
    return f"{x:.4g}"


def check_ball_pairs(balls) -> None:
    """InputError naming ``balls[j].position`` for the first pair (by j, then i, i < j)
    whose bodies overlap at release."""
    if len(balls) < 2:
        return
    from scipy.spatial import cKDTree  # here: most scenes have one ball or none

    centres = np.array([b.position for b in balls])
    radii = np.array([b.radius for b in balls])
    pairs = cKDTree(centres).query_pairs(2.0 * radii.max(), output_type="ndarray")
    if len(pairs) == 0:
        return
    i, j = pairs.min(axis=1), pairs.max(axis=1)
    dist = np.linalg.norm(centres[j] - centres[i], axis=1)
    reach = radii[i] + radii[j]
    bad = np.flatnonzero(dist < reach)
    if len(bad) == 0:
        return
    k = bad[np.lexsort((i[bad], j[bad]))[0]]
    a, b = int(i[k]), int(j[k])
    if dist[k] >= reach[k] * (1.0 - TOUCH_TOLERANCE):
        raise InputError(
            f"balls[{b + 1}].position",
            f"touches balls[{a + 1}] ({balls[a].name!r}) {reach[k] - dist[k]:.2g} m closer than "
            f"the sum of their radii, by the rounding of the written decimals; a contact at "
            "release needs the centres at least r1 + r2 apart: move one away by 1e-9 m",
        )
    raise InputError(
        f"balls[{b + 1}].position",
        f"overlaps balls[{a + 1}] ({balls[a].name!r}): centres {_f(dist[k])} m apart, radii "
        f"{_f(radii[a])} + {_f(radii[b])} m; bodies may touch at release but not overlap",
    )


def undisturbed_path(ball, gravity, duration: float, half_sizes=(math.inf, math.inf)):
    """(t_end, acceleration): the ball's centre is x0 + v t + a t^2 / 2 for t <= t_end s
    (module docstring): free flight until its first plate touch, or sliding on the plate
    (a without its normal part) when it starts on the plate without a normal velocity; in
    both cases no longer than ``duration`` or than its centre stays over the plate
    (``half_sizes`` (a/2, b/2), m: past an edge a ball leaves the plate)."""
    g = np.asarray(gravity, dtype=float)
    gap, vz, gz = ball.gap, ball.velocity[2], g[2]
    if gap <= 0.0 and vz == 0.0 and gz <= 0.0:
        t_touch, g = math.inf, np.array([g[0], g[1], 0.0])
    elif gz < 0.0:
        t_touch = (vz + math.sqrt(vz * vz - 2.0 * gz * max(gap, 0.0))) / -gz
    else:
        t_touch = gap / -vz if vz < 0.0 else math.inf
    t_edge = min(
        _first_reach(ball.position[axis], ball.velocity[axis], g[axis], half_sizes[axis])
        for axis in (0, 1)
    )
    return min(t_touch, t_edge, duration), g


def _first_reach(p0: float, v: float, a: float, half: float) -> float:
    """First t > 0 (s) with |p0 + v t + a t^2 / 2| = half (m), p0 inside; inf if never."""
    if not math.isfinite(half):
        return math.inf
    roots = []
    for h in (half, -half):
        c = p0 - h
        if a == 0.0:
            roots += [-c / v] if v != 0.0 else []
            continue
        disc = v * v - 2.0 * a * c
        if disc >= 0.0:
            q = math.sqrt(disc)
            roots += [(-v - q) / a, (-v + q) / a]
    return min((r for r in roots if r > 0.0), default=math.inf)


def check_particles_against_balls(scene) -> None:
    """InputError naming ``streams[q].area`` for the first stream particle (in release
    order) that overlaps a ball at its release (module docstring)."""
    if not scene.balls:
        return
    particles = scene.particles[len(scene.balls) :]
    if not particles:
        return
    t = np.array([p.t_release for p in particles])
    x = np.array([p.position for p in particles])
    r = np.array([p.radius for p in particles])
    g, half = scene.incline.gravity_vector, scene.incline.half_sizes
    paths = [undisturbed_path(b, g, scene.duration, half) for b in scene.balls]
    ball, k = _candidates(scene.balls, paths, x, t, r.max())
    keep = t[k] <= np.array([p[0] for p in paths])[ball]
    ball, k = ball[keep], k[keep]
    x0 = np.array([b.position for b in scene.balls])[ball]
    v0 = np.array([b.velocity for b in scene.balls])[ball]
    acc = np.array([p[1] for p in paths])[ball]
    tk = t[k][:, None]
    dist = np.linalg.norm(x[k] - (x0 + v0 * tk + 0.5 * acc * tk * tk), axis=1)
    reach = np.array([b.radius for b in scene.balls])[ball] + r[k]
    bad = np.flatnonzero(dist < reach * (1.0 - TOUCH_TOLERANCE))
    if len(bad):
        m = bad[np.lexsort((ball[bad], k[bad]))[0]]  # the earliest particle, then ball order
        _refuse(scene, particles, int(k[m]), int(ball[m]), float(dist[m]))


def _candidates(balls, paths, x, t, r_max):
    """(ball, particle) index pairs, unique, that may overlap. A k-d tree holds the
    particles' release events as points (x, y, z, c t) with c = ``TIME_SCALE``; each ball's
    path is sampled at times dt apart, with its sample points at most r + r_max apart along
    the path and c dt <= r + r_max; every particle that overlaps the ball at its release
    time is within sqrt((r + r_max + step)^2 + (c dt / 2)^2) of the sample nearest that
    time (step: the path's length between samples). The exact test is the caller's."""
    from scipy.spatial import cKDTree

    tree = cKDTree(np.column_stack([x, TIME_SCALE * t]))
    points, owners, reach = [], [], []
    for i, (b, (t_end, acc)) in enumerate(zip(balls, paths, strict=True)):
        v = np.asarray(b.velocity)
        top_speed = float(np.linalg.norm(v) + np.linalg.norm(acc) * t_end)
        spacing = b.radius + r_max
        span = max(top_speed, TIME_SCALE) * t_end
        n = int(min(math.ceil(span / spacing), MAX_SAMPLES)) + 1
        times = np.linspace(0.0, t_end, n)
        where = np.asarray(b.position) + np.outer(times, v) + 0.5 * np.outer(times**2, acc)
        points.append(np.column_stack([where, TIME_SCALE * times]))
        owners.append(np.full(n, i))
        dt = t_end / max(n - 1, 1)
        reach.append(np.full(n, math.hypot(spacing + top_speed * dt, 0.5 * TIME_SCALE * dt)))
    found = tree.query_ball_point(np.concatenate(points), np.concatenate(reach))
    counts = np.fromiter((len(f) for f in found), dtype=int, count=len(found))
    ball = np.repeat(np.concatenate(owners), counts)
    k = np.fromiter((j for f in found for j in f), dtype=int, count=int(counts.sum()))
    pairs = np.unique(np.column_stack([ball, k]), axis=0)
    return pairs[:, 0], pairs[:, 1]


def _refuse(scene, particles, k, i, dist):
    p, ball = particles[k], scene.balls[i]
    q = next(n for n, s in enumerate(scene.streams, start=1) if s.name == p.stream)
    at = ", ".join(_f(c) for c in p.position)
    raise InputError(
        f"streams[{q}].area",
        f"particle {p.name} (released at t = {_f(p.t_release)} s at ({at}) m) overlaps "
        f"balls[{i + 1}] ({ball.name!r}): centres {_f(dist)} m apart, radii "
        f"{_f(p.radius)} + {_f(ball.radius)} m; move the release area or height, or the ball",
    )
