"""Caving streams: coal and gangue particles released over the tail beam.

A stream is given by settings as a user will write them in a scene file (``[[streams]]``
tables; keys below, SI units, plate frame of ``tailbeam.physics.incline``):

    name             text, particles are named <name>-<k>, k = 1, 2, ... in release order
    rate             particles per second (> 0)
    start, stop      release window in s (0 <= start < stop)
    gangue_fraction  probability that a particle is gangue (0..1)
    coal_material, gangue_material   material names (default coal, sandstone)
    radius           [min, max] in m (0 < min <= max)
    size_distribution  "uniform" (default), "lognormal" (median in m, sigma: standard
                     deviation of ln r) or "rosin_rammler" (characteristic_radius r63 in m,
                     uniformity n: P(R <= r) = 1 - exp(-(r / r63)^n)), truncated to [min, max]
    area             [[x0, x1], [y0, y1]]: release area over the plate, m
    height           gap in m between a particle's lowest point and the plate at release:
                     a number or [min, max] (uniform)
    velocity         mean release velocity [vx, vy, vz] in m/s (default [0, 0, 0])
    velocity_spread  standard deviation of each velocity component, m/s (default 0)
    angular_velocity_spread  standard deviation of each angular velocity component (mean
                     0), rad/s (default 0: the particles do not spin)
    seed             integer >= 0 (default 0)
    max_tries        placement attempts per particle (default 100)

Arrivals are a Poisson process (independent exponential gaps of mean 1/rate): given their
number, the release times are uniform on [start, stop).

Randomness: each stream owns numpy Generators on the PCG64 bit generator seeded by
SeedSequence(seed), one per quantity (arrivals, labels, radii, velocities, positions, spins), and
only draws uniform doubles, turned into each distribution by its inverse CDF (scipy.special
ndtr/ndtri for the normal and lognormal). The stream depends on nothing but the seed and the
settings (no dict order, no hashing); PCG64's stream is stable across numpy versions and
platforms, so the same seed gives the same particles up to the last-bit rounding of log/exp.
Two streams with the same seed draw the same numbers: give them different seeds.

Placement without overlap: particles of all streams are placed in release order; a candidate
position is rejected if the particle would overlap one released earlier that is still in
the release zone at that time (its free flight under gravity; once a particle's top is below
the lowest release gap it can no longer overlap a new one and is forgotten, so the check
costs O(particles in the zone), bounded by rate x residence time). After ``max_tries``
rejections an InputError names ``streams[i].area`` (enlarge the area or the height range,
or lower the rate). Collisions between particles after release are the solver's business.
"""

import math
from dataclasses import dataclass, field

import numpy as np

from tailbeam.errors import (
    InputError,
    require_nonnegative,
    require_positive,
    require_real,
    require_vector,
)
from tailbeam.physics.bodies import Ball
from tailbeam.physics.incline import InclinedPlate
from tailbeam.physics.materials import Material, get_material

KEYS = (
    "name", "rate", "start", "stop", "gangue_fraction", "coal_material", "gangue_material",
    "radius", "size_distribution", "median", "sigma", "characteristic_radius", "uniformity",
    "area", "height", "velocity", "velocity_spread", "seed", "max_tries",
    "angular_velocity_spread",
)  # fmt: skip
DISTRIBUTIONS = {
    "uniform": (),
    "lognormal": ("median", "sigma"),
    "rosin_rammler": ("characteristic_radius", "uniformity"),
}
MAX_PARTICLES = 1_000_000  # per stream: expected count rate x (stop - start)


@dataclass(frozen=True)
class StreamSettings:
    """Validated settings of one stream (see the module docstring); ``field`` is how the
    user names it (``streams[1]``)."""

    field: str
    name: str
    rate: float
    start: float
    stop: float
    gangue_fraction: float
    coal_material: Material
    gangue_material: Material
    radius: tuple
    size_distribution: str
    size_parameters: tuple
    area: tuple
    height: tuple
    velocity: tuple
    velocity_spread: float
    seed: int
    max_tries: int
    angular_velocity_spread: float = 0.0


SLOT_KEY = 6  # spawn key of the free-slot draws (the six quantities use 0-5)


@dataclass(frozen=True)
class ReleaseSlot:
    """Where particle ``index`` (k - 1) of a stream may be released: its centre over ``area``
    (m) with a gap in ``height`` (m) below it; candidates for a free slot at the release time
    come from the particle's own Generator (PCG64, SeedSequence(seed, spawn_key=(SLOT_KEY,
    index))), so they depend on the seed and k alone."""

    area: tuple
    height: tuple
    seed: int
    index: int
    max_tries: int

    def candidates(self, radius: float) -> np.ndarray:
        """``max_tries`` candidate centres (m, max_tries x 3) for a particle of ``radius`` (m),
        drawn as the generator draws a release position."""
        seq = np.random.SeedSequence(self.seed, spawn_key=(SLOT_KEY, self.index))
        u = np.random.Generator(np.random.PCG64(seq)).random((self.max_tries, 3))
        (x0, x1), (y0, y1) = self.area
        h0, h1 = self.height
        return np.column_stack(
            [x0 + u[:, 0] * (x1 - x0), y0 + u[:, 1] * (y1 - y0), radius + h0 + u[:, 2] * (h1 - h0)]
        )


@dataclass(frozen=True)
class Particle:
    """A released particle: position (m), velocity (m/s) and angular velocity (rad/s) at its
    release time t_release; ``slot``: where a solver may move its release if a ball is in the
    way (None: nowhere)."""

    name: str
    stream: str
    label: str
    material: Material
    radius: float
    mass: float
    t_release: float
    position: tuple
    velocity: tuple
    angular_velocity: tuple = (0.0, 0.0, 0.0)
    slot: ReleaseSlot | None = field(default=None, compare=False, repr=False)

    def ball(self) -> Ball:
        """The particle as a ``tailbeam.Ball`` at its release state."""
        return Ball(self.name, self.material, self.radius, self.position, self.velocity,
                    self.angular_velocity)  # fmt: skip

    @classmethod
    def from_ball(cls, ball: Ball, label: str) -> "Particle":
        """A ``[[balls]]`` entry as a particle: no stream, released at 0 s, labelled ``label``."""
        return cls(ball.name, "", label, ball.material, ball.radius, ball.mass, 0.0,
                   ball.position, ball.velocity, ball.angular_velocity)  # fmt: skip


def default_label(ball: Ball) -> str:
    """``coal`` for a ball of the material named coal, ``gangue`` otherwise."""
    return "coal" if ball.material.name == "coal" else "gangue"


def balls_as_particles(balls, labels=()) -> tuple:
    """``[[balls]]`` as ``Particle``s (``Particle.from_ball``), labelled ``labels`` (coal /
    gangue per ball; empty: ``default_label``)."""
    labels = tuple(labels) or tuple(default_label(b) for b in balls)
    return tuple(Particle.from_ball(b, label) for b, label in zip(balls, labels, strict=True))


def parse_stream(settings: dict, index: int, incline: InclinedPlate, materials=None):
    """Validate the settings of stream number ``index`` (1-based, as the user counts)."""
    field = f"streams[{index}]"
    if not isinstance(settings, dict):
        raise InputError(field, "must be a table of settings")
    unknown = sorted(set(settings) - set(KEYS))
    if unknown:
        raise InputError(f"{field}.{unknown[0]}", f"unknown key; known keys: {', '.join(KEYS)}")
    get = _getter(settings, field)
    name = get("name", None)
    if not isinstance(name, str) or not name.strip():
        raise InputError(f"{field}.name", f"must be a non-empty text, got {name!r}")
    rate = require_positive(f"{field}.rate", get("rate", None))
    start = require_nonnegative(f"{field}.start", get("start", 0.0))
    stop = require_real(f"{field}.stop", get("stop", None))
    if stop <= start:
        raise InputError(f"{field}.stop", f"must be > start = {start!r}, got {stop!r}")
    if rate * (stop - start) > MAX_PARTICLES:
        raise InputError(
            f"{field}.rate",
            f"rate x (stop - start) = {rate * (stop - start):.3g} particles exceeds the limit "
            f"{MAX_PARTICLES}; lower the rate or shorten start..stop",
        )
    fraction = require_real(f"{field}.gangue_fraction", get("gangue_fraction", None))
    if not 0.0 <= fraction <= 1.0:
        raise InputError(f"{field}.gangue_fraction", f"must lie in [0, 1], got {fraction!r}")
    coal = get_material(get("coal_material", "coal"), materials, field=f"{field}.coal_material")
    gangue = get_material(
        get("gangue_material", "sandstone"), materials, field=f"{field}.gangue_material"
    )
    radius = _range(f"{field}.radius", get("radius", None), positive=True)
    dist, params = _size_distribution(settings, field, radius)
    area = _area(f"{field}.area", get("area", None), incline)
    height = _height(f"{field}.height", get("height", None))
    velocity = require_vector(f"{field}.velocity", get("velocity", (0.0, 0.0, 0.0)), 3)
    spread = require_nonnegative(f"{field}.velocity_spread", get("velocity_spread", 0.0))
    seed = _integer(f"{field}.seed", get("seed", 0), minimum=0)
    tries = _integer(f"{field}.max_tries", get("max_tries", 100), minimum=1)
    spin = require_nonnegative(
        f"{field}.angular_velocity_spread", get("angular_velocity_spread", 0.0)
    )
    return StreamSettings(
        field, name.strip(), rate, start, stop, fraction, coal, gangue, radius, dist, params,
        area, height, velocity, spread, seed, tries, spin,
    )  # fmt: skip


MAX_FILL = 0.15  # largest share of the release volume the falling particles may fill. Measured
# on 30-degree streams of 10-40 mm lumps (drops 20-100 mm, 50 mm, 100-150 mm, 0.3-0.8 m): the
# placement below succeeds for 20 of 20 seeds at 10 %, fails for 0-30 % of them at 12 %,
# 0-70 % at 15 %, 35-100 % at 20 % (then its own max_tries error names the same key)


def release_fill(s: StreamSettings, incline: InclinedPlate) -> tuple[float, float]:
    """(fill, residence): the share of the release volume that the stream's falling particles
    fill on average, rate x E[residence x particle volume] / release volume (Little's law),
    and the mean residence (s). A particle resides from its release until its top falls
    below the lowest release gap (mean release velocity, no rebounds; at most stop - start).
    The release volume holds every released body: (x1 - x0 + 2 r_max)(y1 - y0 + 2 r_max)
    (h1 - h0 + 2 r_max). Means over 32 x 32 midpoint quantiles of the gap and the radius."""
    u = (np.arange(32) + 0.5) / 32
    r = _radii(s, u)[:, None]
    h0, h1 = s.height
    h = (h0 + u * (h1 - h0))[None, :]
    drop = h + 2.0 * r - h0  # m the top falls to leave
    g_n, vz = -float(incline.gravity_vector[2]), -float(s.velocity[2])  # vz: downward speed
    if g_n > 0.0:
        t = (-vz + np.sqrt(vz * vz + 2.0 * g_n * drop)) / g_n
    else:
        t = np.where(vz > 0.0, drop / max(vz, 1e-300), np.inf)
    t = np.minimum(t, s.stop - s.start)
    (x0, x1), (y0, y1) = s.area
    r_max = s.radius[1]
    volume = (x1 - x0 + 2 * r_max) * (y1 - y0 + 2 * r_max) * (h1 - h0 + 2 * r_max)
    filled = s.rate * np.mean(t * 4.0 / 3.0 * math.pi * r**3)
    return float(filled / volume), float(np.mean(t))


def _check_fill(s: StreamSettings, incline: InclinedPlate) -> None:
    fill, residence = release_fill(s, incline)
    if fill > MAX_FILL:
        raise InputError(
            f"{s.field}.area",
            f"too crowded for the flow: {s.rate:g} particles/s staying ~{residence:.3g} s each "
            f"fill {fill:.0%} of the release volume (at most {MAX_FILL:.0%}, so each release "
            "finds a free place at its time); enlarge the area or the height range, or lower "
            "the rate",
        )


def _getter(settings, field):
    def get(key, default):
        if key in settings:
            return settings[key]
        if default is None:
            raise InputError(f"{field}.{key}", "is required")
        return default

    return get


def _integer(field, value, minimum):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise InputError(field, f"must be an integer >= {minimum}, got {value!r}")
    return int(value)


def _range(field, value, positive=False):
    lo, hi = require_vector(field, value, 2)
    if positive and lo <= 0.0:
        raise InputError(field, f"must be > 0, got {lo!r}")
    if hi < lo:
        raise InputError(field, f"must be [min, max] with min <= max, got {[lo, hi]!r}")
    return lo, hi


def _height(field, value):
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        h = require_positive(field, value)
        return h, h
    lo, hi = _range(field, value)
    if lo <= 0.0:
        raise InputError(field, f"must be > 0 (a gap above the plate), got {lo!r}")
    return lo, hi


def _area(field, value, incline):
    try:
        x_range, y_range = value
        len(x_range), len(y_range)
    except (TypeError, ValueError):
        raise InputError(field, f"must be [[x0, x1], [y0, y1]], got {value!r}") from None
    (x0, x1), (y0, y1) = _range(f"{field}[0]", x_range), _range(f"{field}[1]", y_range)
    ha, hb = incline.half_sizes
    if x0 < -ha or x1 > ha or y0 < -hb or y1 > hb:
        raise InputError(
            field, f"must lie over the plate (x in [{-ha}, {ha}], y in [{-hb}, {hb}] m)"
        )
    return (x0, x1), (y0, y1)


def _size_distribution(settings, field, radius):
    dist = settings.get("size_distribution", "uniform")
    if dist not in DISTRIBUTIONS:
        known = ", ".join(DISTRIBUTIONS)
        raise InputError(f"{field}.size_distribution", f"must be one of {known}, got {dist!r}")
    for key in ("median", "sigma", "characteristic_radius", "uniformity"):
        if key in settings and key not in DISTRIBUTIONS[dist]:
            raise InputError(f"{field}.{key}", f"is not a parameter of {dist!r}")
    params = tuple(
        require_positive(f"{field}.{key}", _getter(settings, field)(key, None))
        for key in DISTRIBUTIONS[dist]
    )
    if dist != "uniform" and radius[0] == radius[1]:
        raise InputError(f"{field}.radius", f"min < max is needed for {dist!r}")
    if dist != "uniform" and np.ptp(_cdf(dist, params, np.array(radius))) <= 1e-12:
        raise InputError(f"{field}.radius", f"[min, max] holds (almost) no {dist!r} mass")
    return dist, params


def _cdf(dist, params, r):
    """P(R <= r) of the untruncated distribution."""
    if dist == "lognormal":
        from scipy.special import ndtr  # here: only a lognormal stream pays its import

        median, sigma = params
        return ndtr(np.log(r / median) / sigma)
    r63, n = params
    return -np.expm1(-((r / r63) ** n))


def _inverse_cdf(dist, params, p):
    if dist == "lognormal":
        from scipy.special import ndtri

        median, sigma = params
        return median * np.exp(sigma * ndtri(p))
    r63, n = params
    return r63 * (-np.log1p(-p)) ** (1.0 / n)


def radius_cdf(s: StreamSettings, r):
    """P(R <= r) of the stream's truncated radius distribution (for tests and docs)."""
    lo, hi = s.radius
    r = np.clip(np.asarray(r, dtype=float), lo, hi)
    if s.size_distribution == "uniform":
        return (r - lo) / (hi - lo) if hi > lo else np.where(r >= hi, 1.0, 0.0)
    f_lo, f_hi = _cdf(s.size_distribution, s.size_parameters, np.array([lo, hi]))
    return (_cdf(s.size_distribution, s.size_parameters, r) - f_lo) / (f_hi - f_lo)


def _radii(s: StreamSettings, u):
    lo, hi = s.radius
    if s.size_distribution == "uniform":
        return lo + u * (hi - lo)
    f_lo, f_hi = _cdf(s.size_distribution, s.size_parameters, np.array([lo, hi]))
    r = _inverse_cdf(s.size_distribution, s.size_parameters, f_lo + u * (f_hi - f_lo))
    return np.clip(r, lo, hi)


@dataclass
class _Draws:
    """The per-particle random quantities of one stream, before placement."""

    settings: StreamSettings
    times: np.ndarray
    gangue: np.ndarray
    radii: np.ndarray
    velocities: np.ndarray
    position_rng: np.random.Generator
    spins: np.ndarray


def _draw(s: StreamSettings) -> _Draws:
    from scipy.special import ndtri

    # the sixth child leaves the first five, and so every other quantity, as they were
    gens = [
        np.random.Generator(np.random.PCG64(c)) for c in np.random.SeedSequence(s.seed).spawn(6)
    ]
    arrivals, labels, sizes, speeds, places, turns = gens
    times, t = [], s.start
    while True:  # Poisson process: exponential gaps, drawn in blocks
        gaps = -np.log1p(-arrivals.random(256)) / s.rate
        cum = t + np.cumsum(gaps)
        times.extend(cum[cum < s.stop])
        if cum[-1] >= s.stop:
            break
        t = cum[-1]
    n = len(times)
    gangue = labels.random(n) < s.gangue_fraction
    radii = _radii(s, sizes.random(n))
    normal = ndtri(speeds.random((n, 3)))
    velocities = np.asarray(s.velocity) + s.velocity_spread * normal
    spins = np.zeros((n, 3))
    if s.angular_velocity_spread > 0.0:
        spins = s.angular_velocity_spread * ndtri(turns.random((n, 3)))
    return _Draws(s, np.array(times), gangue, radii, velocities, places, spins)


def generate_particles(streams, incline: InclinedPlate, materials=None) -> list:
    """Particles of all ``streams`` (a list of settings mappings, ``streams[1]`` first),
    in release order (ties: stream order, then k). See the module docstring."""
    parsed = [parse_stream(s, i, incline, materials) for i, s in enumerate(streams, start=1)]
    return particles_from_settings(parsed, incline)


def particles_from_settings(parsed, incline: InclinedPlate) -> list:
    """``generate_particles`` for streams already validated by ``parse_stream``."""
    names = [p.name for p in parsed]
    for i, name in enumerate(names):
        if name in names[:i]:
            raise InputError(f"streams[{i + 1}].name", f"{name!r} is used by an earlier stream")
    for s in parsed:  # before any draw: a flow the release volume cannot take
        _check_fill(s, incline)
    draws = [_draw(s) for s in parsed]
    order = sorted(
        ((t, q, k) for q, d in enumerate(draws) for k, t in enumerate(d.times)),
    )
    floor = min(s.height[0] for s in parsed)  # the lowest release gap of all streams
    zone = _Zone(incline.gravity_vector, floor)
    particles = []
    for t, q, k in order:
        particles.append(_place(draws[q], k, t, zone))
    return particles


class _Zone:
    """Particles released so far that may still be in the release zone (free flights)."""

    def __init__(self, gravity, floor):
        self.g, self.floor = np.asarray(gravity), floor
        self.x = np.empty((0, 3))
        self.v = np.empty((0, 3))
        self.t = np.empty(0)
        self.r = np.empty(0)

    def at(self, t):
        """Centres (m) at time t of the particles still in the zone, and their radii."""
        dt = (t - self.t)[:, None]
        x = self.x + self.v * dt + 0.5 * self.g * dt * dt
        keep = x[:, 2] + self.r >= self.floor  # else below every release: forget it
        self.x, self.v, self.t, self.r = self.x[keep], self.v[keep], self.t[keep], self.r[keep]
        return x[keep], self.r

    def add(self, t, x, v, r):
        self.x = np.vstack([self.x, x])
        self.v = np.vstack([self.v, v])
        self.t = np.append(self.t, t)
        self.r = np.append(self.r, r)


def _place(d: _Draws, k: int, t: float, zone: _Zone) -> Particle:
    s = d.settings
    r = float(d.radii[k])
    centres, radii = zone.at(t)
    (x0, x1), (y0, y1) = s.area
    h0, h1 = s.height
    for _ in range(s.max_tries):
        u = d.position_rng.random(3)
        x = np.array([x0 + u[0] * (x1 - x0), y0 + u[1] * (y1 - y0), r + h0 + u[2] * (h1 - h0)])
        if len(radii) == 0 or np.all(np.sum((centres - x) ** 2, axis=1) > (radii + r) ** 2):
            break
    else:
        raise InputError(
            f"{s.field}.area",
            f"too crowded: particle {s.name}-{k + 1} (released at t = {t:.6g} s, radius "
            f"{r:.4g} m) overlaps particles still in the release zone after {s.max_tries} "
            "tries; enlarge the area or the height range, or lower the rate",
        )
    v = d.velocities[k]
    zone.add(t, x, v, r)
    gangue = bool(d.gangue[k])
    material = s.gangue_material if gangue else s.coal_material
    mass = material.density * 4.0 / 3.0 * math.pi * r**3
    slot = ReleaseSlot(s.area, s.height, s.seed, k, s.max_tries)
    return Particle(
        f"{s.name}-{k + 1}", s.name, "gangue" if gangue else "coal", material, r, mass,
        float(t), tuple(float(c) for c in x), tuple(float(c) for c in v),
        tuple(float(c) for c in d.spins[k]), slot,
    )  # fmt: skip
