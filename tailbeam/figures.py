"""Figures of the paper's reproduction (analogues of its Figs. 2-10) and of the claim map.

Plotting lives here, out of the physics modules. Figures are built with matplotlib's
object-oriented API (``matplotlib.figure.Figure``, rendered by Agg), so no GUI backend or
global pyplot state is involved.
"""

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

# The paper's figure numbers: (position, velocity, force) per scenario.
PAPER_FIGURES = {"velocity": (2, 3, 4), "material": (5, 6, 7), "energy": (8, 9, 10)}
QUANTITIES = (
    ("z", "position: centre height z (m)", "position"),
    ("vz", "velocity v_z (m/s)", "velocity"),
    ("force", "contact force (N)", "force"),
)


def scenario_figures(result, scenario, out_dir, *, sample_rate: float = 20000.0) -> list:
    """Three PNGs (position, velocity, force vs time; both balls on one axes) for a scenario.

    Sampled on ``result.time_grid(sample_rate)``, which contains every impact's peak time, so
    the short force pulses keep their true peaks.
    """
    out_dir = Path(out_dir)
    t = result.time_grid(sample_rate)
    states = result.sample(t)
    paths = []
    numbers = PAPER_FIGURES.get(scenario.key, (0, 0, 0))
    for (key, label, word), number in zip(QUANTITIES, numbers, strict=True):
        fig = Figure(figsize=(7.0, 3.6), layout="constrained")
        ax = fig.add_subplot()
        for name, s in states.items():
            ax.plot(t, s[key], lw=0.8, label=name)
        ax.set_xlabel("time t (s)")
        ax.set_ylabel(label)
        ax.set_title(
            f"Sec. {scenario.section} (cf. paper Fig. {number}): {scenario.title}", fontsize=9
        )
        ax.legend(loc="upper right")
        ax.grid(alpha=0.3)
        path = out_dir / f"fig{number:02d}_{scenario.key}_{word}.png"
        fig.savefig(path, dpi=120)
        paths.append(path)
    return paths


def claim_map_figure(path, gaps, dampings, penetrations, pass_count, n_claims, defaults=None):
    """One panel per drop gap: number of claims that hold over (c, d).

    ``pass_count[g, i, j]`` for gaps[g], dampings[i], penetrations[j]; ``defaults`` = (c, d, gap)
    is marked in its panel.
    """
    n = len(gaps)
    cols = min(n, 4)
    rows = (n + cols - 1) // cols
    fig = Figure(figsize=(3.4 * cols + 1.0, 3.0 * rows), layout="constrained")
    axes = fig.subplots(rows, cols, squeeze=False)
    mesh = None
    for g, gap in enumerate(gaps):
        ax = axes[g // cols][g % cols]
        mesh = ax.pcolormesh(
            penetrations,
            dampings,
            pass_count[g],
            vmin=0,
            vmax=n_claims,
            cmap="viridis",
            shading="nearest",
        )
        full = np.asarray(pass_count[g]) == n_claims
        ii, jj = np.nonzero(full)
        ax.plot(np.asarray(penetrations)[jj], np.asarray(dampings)[ii], "w*", ms=5)
        if defaults is not None and np.isclose(gap, defaults[2]):
            ax.plot(defaults[1], defaults[0], "rx", ms=10, mew=2)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_title(f"drop gap {gap * 1000:g} mm", fontsize=9)
        ax.set_xlabel("penetration d (m)")
        ax.set_ylabel("damping c (N s/m)")
    for k in range(n, rows * cols):
        axes[k // cols][k % cols].set_visible(False)
    fig.colorbar(mesh, ax=axes, label=f"claims holding (of {n_claims}); * = all; x = defaults")
    fig.savefig(path, dpi=110)
    return Path(path)


def sensor_figure(output, path) -> Path:
    """One sensor's record: sampled acceleration vs time beside its amplitude spectrum (up to
    the sensor's bandwidth). ``output`` is a tailbeam.sensor.SensorOutput."""
    fig = Figure(figsize=(10.0, 3.6), layout="constrained")
    ax_t, ax_f = fig.subplots(1, 2)
    ax_t.plot(output.t * 1e3, output.acceleration, lw=0.6)
    ax_t.set_xlabel("time t (ms)")
    ax_t.set_ylabel("acceleration (m/s$^2$)")
    ax_t.set_title(f"sensor {output.name}: {output.chain.sample_rate:g} Hz samples", fontsize=9)
    ax_f.semilogy(output.freq / 1e3, np.maximum(output.amplitude, 1e-9), lw=0.6)
    ax_f.set_xlim(0.0, output.chain.bandwidth_hz / 1e3)
    ax_f.set_xlabel("frequency (kHz)")
    ax_f.set_ylabel("amplitude (m/s$^2$)")
    ax_f.set_title(f"spectrum, usable band to {output.chain.bandwidth_hz:g} Hz", fontsize=9)
    for ax in (ax_t, ax_f):
        ax.grid(alpha=0.3)
    path = Path(path)
    fig.savefig(path, dpi=120)
    return path
