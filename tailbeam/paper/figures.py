"""Figures of the paper's reproduction (analogues of its Figs. 2-10, plus per-collision and
single-pulse figures) and of the claim map.

Plotting lives here, out of the physics modules. Figures are built with matplotlib's
object-oriented API (``matplotlib.figure.Figure``, rendered by Agg), so no GUI backend or
global pyplot state is involved. Every number drawn comes from the result object (the impact
table or the stored trajectories), never from a separate computation.
"""

from pathlib import Path

import numpy as np
from matplotlib.colors import BoundaryNorm
from matplotlib.figure import Figure
from matplotlib.lines import Line2D

# The paper's figure numbers: (position, velocity, force) per scenario.
PAPER_FIGURES = {"velocity": (2, 3, 4), "material": (5, 6, 7), "energy": (8, 9, 10)}
QUANTITIES = (
    ("z", "position: centre height z (m)", "position"),
    ("vz", "velocity v_z (m/s)", "velocity"),
    ("force", "contact force (N)", "force"),
)
MARKERS = ("o", "^", "s", "D")
MAX_MARKED_IMPACTS = 40  # per ball: mark each peak in the force figure up to this many
ZOOM_SAMPLES = 1500  # samples in the zoom on the first contacts
DPI = 120
ALL_HOLD = {"marker": "*", "ls": "none", "ms": 5, "mfc": "white", "mec": "black", "mew": 0.5}


def _colour(i: int) -> str:
    return f"C{i % 10}"


def _save(fig: Figure, path) -> Path:
    path = Path(path)
    fig.savefig(path, dpi=DPI)
    return path


def _title(scenario, number=None) -> str:
    paper = f" (cf. paper Fig. {number})" if number else ""
    return f"Sec. {scenario.section}{paper}: {scenario.title}"


def plot_grid(result, sample_rate: float) -> np.ndarray:
    """Uniform times at ``sample_rate`` (Hz) on [0, duration] merged with every impact's peak
    time (s), so the short force pulses keep their true peaks at any rate."""
    n = int(np.floor(result.duration * sample_rate * (1.0 + 1e-12))) + 1
    grid = np.arange(n, dtype=float) / sample_rate
    peaks = [imp.t_peak for imp in result.impacts if 0.0 <= imp.t_peak <= result.duration]
    return np.unique(np.concatenate([grid[grid <= result.duration], peaks]))


def _ball_order(result) -> list:
    """(index, name) of the balls, the one with the largest peak force first: drawn first, so
    the smaller pulses lie on top of the larger ones."""
    names = [b.name for b in result.particles]

    def peak(name):
        return max((imp.peak_force for imp in result.impacts_of(name)), default=0.0)

    return sorted(enumerate(names), key=lambda item: -peak(item[1]))


def _zoom_window(result) -> tuple:
    """[t0, t1] (s) holding the first contact of every ball, padded by a fifth of the longest."""
    firsts = [imps[0] for b in result.particles if (imps := result.impacts_of(b.name))]
    if not firsts:
        return None
    t0 = min(imp.t_start for imp in firsts)
    t1 = max(min(imp.t_end, result.duration) for imp in firsts)
    pad = 0.2 * max(min(imp.t_end, result.duration) - imp.t_start for imp in firsts)
    return max(0.0, t0 - pad), min(result.duration, t1 + pad)


def _force_axes(ax, result, t, states, *, time_scale=1.0, mark=True):
    """Force against time, larger pulses underneath; open markers on the tabulated peaks."""
    for i, name in _ball_order(result):
        colour, marker = _colour(i), MARKERS[i % len(MARKERS)]
        ax.plot(t * time_scale, states[name]["force"], lw=0.9, color=colour, label=name)
        imps = result.impacts_of(name)
        if mark and len(imps) <= MAX_MARKED_IMPACTS:
            tp = np.array([imp.t_peak for imp in imps])
            fp = np.array([imp.peak_force for imp in imps])
            ax.plot(tp * time_scale, fp, marker, ls="none", ms=6, mfc="none", color=colour)


def force_figure(result, scenario, t, states, number) -> Figure:
    """The whole force record (markers on every peak) beside a zoom on the first contacts."""
    fig = Figure(figsize=(10.0, 3.8), layout="constrained")
    ax, ax_zoom = fig.subplots(1, 2, width_ratios=(2.2, 1.0))
    _force_axes(ax, result, t, states)
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("contact force (N)")
    marked = all(len(result.impacts_of(b.name)) <= MAX_MARKED_IMPACTS for b in result.particles)
    note = "markers: peaks of impacts.csv" if marked else f"peaks: collisions_{scenario.key}.png"
    ax.set_title(f"whole record; {note}", fontsize=9)
    handles = [
        Line2D(
            [],
            [],
            color=_colour(i),
            marker=MARKERS[i % len(MARKERS)] if marked else None,
            mfc="none",
            label=n,
        )
        for i, n in enumerate(b.name for b in result.particles)
    ]
    ax.legend(handles=handles, loc="upper right")
    window = _zoom_window(result)
    if window is not None:
        tz = np.unique(
            np.concatenate(
                [
                    np.linspace(*window, ZOOM_SAMPLES),
                    [imp.t_peak for imp in result.impacts if window[0] <= imp.t_peak <= window[1]],
                ]
            )
        )
        _force_axes(ax_zoom, result, tz, result.sample(tz), time_scale=1e3)
        ax_zoom.set_xlim(window[0] * 1e3, window[1] * 1e3)
    ax_zoom.set_xlabel("time t (ms)")
    ax_zoom.set_ylabel("contact force (N)")
    ax_zoom.set_title("zoom: first contact of each ball", fontsize=9)
    for a in (ax, ax_zoom):
        a.grid(alpha=0.3)
    fig.suptitle(_title(scenario, number), fontsize=10)
    return fig


def time_figure(result, scenario, t, states, key, label, number) -> Figure:
    """One quantity of every ball against time on one axes (the ball with the larger impacts
    drawn first); a note names the per-collision figure when the collisions are too many to
    tell apart."""
    fig = Figure(figsize=(7.0, 3.6), layout="constrained")
    ax = fig.add_subplot()
    for i, name in _ball_order(result):
        ax.plot(t, states[name][key], lw=0.8, color=_colour(i), label=name)
    ax.set_xlabel("time t (s)")
    ax.set_ylabel(label)
    title = _title(scenario, number)
    if max(len(result.impacts_of(b.name)) for b in result.particles) > MAX_MARKED_IMPACTS:
        title += (
            f"\nper collision: collisions_{scenario.key}.png; one pulse: pulse_{scenario.key}.png"
        )
    ax.set_title(title, fontsize=9)
    handles, names = ax.get_legend_handles_labels()
    order = np.argsort([[b.name for b in result.particles].index(n) for n in names])
    ax.legend(  # outside the axes: the curves fill the whole record
        [handles[k] for k in order],
        [names[k] for k in order],
        loc="upper left",
        bbox_to_anchor=(1.01, 1.0),
    )
    ax.grid(alpha=0.3)
    return fig


COLLISION_PANELS = (
    ("peak_force", "peak contact force (N)", 1.0),
    ("next_apex_height", "rebound height after collision n (mm)", 1e3),
    ("restitution", "restitution e = v_out / v_in", 1.0),
)


def collision_series(result, name: str, field: str) -> tuple:
    """Collision numbers and ``field`` of ball ``name``'s impacts, nan values left out."""
    imps = result.impacts_of(name)
    n = np.array([imp.index for imp in imps], dtype=int)
    y = np.array([getattr(imp, field) for imp in imps], dtype=float)
    keep = np.isfinite(y)
    return n[keep], y[keep]


def collision_figure(result, scenario) -> Figure:
    """Peak force, rebound height and restitution of every ball against collision number:
    the quantities the paper's claims compare collision by collision (impacts.csv)."""
    fig = Figure(figsize=(11.0, 3.6), layout="constrained")
    axes = fig.subplots(1, len(COLLISION_PANELS))
    n_max = max((len(result.impacts_of(b.name)) for b in result.particles), default=0)
    for ax, (field, label, scale) in zip(axes, COLLISION_PANELS, strict=True):
        for i, name in enumerate(b.name for b in result.particles):
            n, y = collision_series(result, name, field)
            style = {"marker": MARKERS[i % len(MARKERS)], "ms": 4 if n_max <= 60 else 2}
            ax.plot(n, y * scale, lw=0.8, color=_colour(i), label=name, **style)
        if n_max > 60:  # hundreds of collisions: log axes show the first ones and the tail
            ax.set_xscale("log")
            if field != "restitution":
                ax.set_yscale("log")
        else:
            ax.xaxis.get_major_locator().set_params(integer=True)
        ax.set_xlabel("collision number n")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3, which="both" if n_max > 60 else "major")
    axes[0].legend()
    fig.suptitle(_title(scenario) + " - per collision (impacts.csv)", fontsize=10)
    return fig


def first_pulses(result) -> dict:
    """name -> (time since contact start (s), penetration (m), force (N)) over the ball's
    first contact, sampled from the stored solution."""
    out = {}
    for ball in result.particles:
        imps = result.impacts_of(ball.name)
        if not imps:
            continue
        imp = imps[0]
        t = np.linspace(imp.t_start, min(imp.t_end, result.duration), ZOOM_SAMPLES)
        t = np.unique(np.concatenate([t, [imp.t_peak]]))
        state = result.sample(t)[ball.name]
        out[ball.name] = (t - imp.t_start, ball.radius - state["z"], state["force"])
    return out


def pulse_figure(result, scenario) -> Figure:
    """Zoom on one pulse per ball (its first contact): force against time since contact start,
    and force against penetration (the loop's area is the energy the contact dissipates)."""
    fig = Figure(figsize=(10.0, 3.8), layout="constrained")
    ax_t, ax_d = fig.subplots(1, 2)
    pulses = first_pulses(result)
    for i, name in enumerate(b.name for b in result.particles):
        if name not in pulses:
            continue
        tau, delta, force = pulses[name]
        imp = result.impacts_of(name)[0]
        label = f"{name}: {imp.peak_force:.0f} N peak, {tau[-1] * 1e6:.0f} µs"
        marker = MARKERS[i % len(MARKERS)]
        ax_t.plot(tau * 1e6, force, color=_colour(i), lw=1.2, label=label)
        ax_t.plot((imp.t_peak - imp.t_start) * 1e6, imp.peak_force, marker, color=_colour(i))
        ax_d.plot(delta * 1e6, force, color=_colour(i), lw=1.2, label=name)
    ax_t.set_xlabel("time since contact start (µs)")
    ax_t.set_ylabel("contact force (N)")
    ax_t.set_title("first contact of each ball\n(marker: peak force in impacts.csv)", fontsize=9)
    ax_t.legend(fontsize=8)
    ax_d.legend(fontsize=8, loc="upper left")
    ax_d.set_xlabel("penetration δ (µm)")
    ax_d.set_ylabel("contact force (N)")
    ax_d.set_title(
        "force against penetration\n(upper branch: loading; loop area = energy lost)", fontsize=9
    )
    for a in (ax_t, ax_d):
        a.grid(alpha=0.3)
        a.set_ylim(bottom=0.0)
    fig.suptitle(_title(scenario) + " - one pulse", fontsize=10)
    return fig


def scenario_figures(result, scenario, out_dir, *, sample_rate: float = 20000.0) -> list:
    """The figures of one scenario; returns their paths.

    fig<NN>_<key>_{position,velocity,force}.png (the paper's Figs. 2-10; the force figure adds
    peak markers and a zoom on the first contacts), collisions_<key>.png (peak force, rebound
    height and restitution against collision number) and pulse_<key>.png (one pulse per ball).
    """
    out_dir = Path(out_dir)
    t = plot_grid(result, sample_rate)
    states = result.sample(t)
    paths = []
    numbers = PAPER_FIGURES.get(scenario.key, (0, 0, 0))
    for (key, label, word), number in zip(QUANTITIES, numbers, strict=True):
        if key == "force":
            fig = force_figure(result, scenario, t, states, number)
        else:
            fig = time_figure(result, scenario, t, states, key, label, number)
        paths.append(_save(fig, out_dir / f"fig{number:02d}_{scenario.key}_{word}.png"))
    paths.append(
        _save(collision_figure(result, scenario), out_dir / f"collisions_{scenario.key}.png")
    )
    paths.append(_save(pulse_figure(result, scenario), out_dir / f"pulse_{scenario.key}.png"))
    return paths


def log_edges(centres) -> np.ndarray:
    """Cell edges (positive) around positive, increasing ``centres`` on a log axis: geometric
    midpoints inside, the neighbouring ratio mirrored at both ends (one centre: x/÷ 2)."""
    c = np.asarray(centres, dtype=float)
    if c.size == 1:
        return np.array([c[0] / 2.0, c[0] * 2.0])
    mid = np.sqrt(c[:-1] * c[1:])
    return np.concatenate([[c[0] ** 2 / mid[0]], mid, [c[-1] ** 2 / mid[-1]]])


def claim_map_figure(path, gaps, dampings, penetrations, pass_count, n_claims, defaults=None):
    """Write build_claim_map_figure(...) to ``path`` (PNG); returns the path."""
    fig = build_claim_map_figure(gaps, dampings, penetrations, pass_count, n_claims, defaults)
    fig.savefig(path, dpi=110)
    return Path(path)


def build_claim_map_figure(gaps, dampings, penetrations, pass_count, n_claims, defaults=None):
    """One panel per drop gap: number of claims that hold over (c, d).

    ``pass_count[g, i, j]`` for gaps[g], dampings[i] (N s/m), penetrations[j] (m); ``defaults``
    = (c, d, gap) is marked in its panel. Cells span geometric midpoints (log_edges), so both
    log axes stay positive; colours span the counts that occur, up to ``n_claims``.
    """
    n = len(gaps)
    cols = min(n, 4)
    rows = (n + cols - 1) // cols
    fig = Figure(figsize=(3.4 * cols + 1.2, 3.0 * rows + 0.6), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False)
    low = int(min(np.min(pass_count), n_claims - 1))  # colours span the counts that occur
    norm = BoundaryNorm(np.arange(low - 0.5, n_claims + 1.0), 256)
    x_edges, y_edges = log_edges(penetrations), log_edges(dampings)
    mesh = None
    for g, gap in enumerate(gaps):
        ax = axes[g // cols][g % cols]
        mesh = ax.pcolormesh(x_edges, y_edges, pass_count[g], norm=norm, cmap="viridis")
        ii, jj = np.nonzero(np.asarray(pass_count[g]) == n_claims)
        ax.plot(np.asarray(penetrations)[jj], np.asarray(dampings)[ii], **ALL_HOLD)
        if defaults is not None and np.isclose(gap, defaults[2]):
            ax.plot(defaults[1], defaults[0], "s", ms=11, mfc="none", mec="red", mew=2)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlim(x_edges[0], x_edges[-1])
        ax.set_ylim(y_edges[0], y_edges[-1])
        ax.set_title(f"drop gap {gap * 1000:g} mm", fontsize=9)
        ax.set_xlabel("penetration d (m)")
        ax.set_ylabel("damping c (N s/m)")
    for k in range(n, rows * cols):
        axes[k // cols][k % cols].set_visible(False)
    step = max(1, int(np.ceil((n_claims - low + 1) / 10)))
    ticks = np.arange(n_claims, low - 1, -step)[::-1]  # integers, the top one = n_claims
    fig.colorbar(mesh, ax=axes, label=f"claims holding (of {n_claims})", ticks=ticks)
    handles = [
        Line2D([], [], **ALL_HOLD, label=f"all {n_claims} claims hold"),
        Line2D([], [], marker="s", ls="none", mfc="none", mec="red", mew=2, label="defaults"),
    ]
    fig.legend(handles=handles, loc="outside lower center", ncols=2, fontsize=8)
    return fig
