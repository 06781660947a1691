"""What friction does to a caving stream on the 30 degree tail beam.

The reference scene's stream (``examples/caving_stream.toml``: coal and 30 % sandstone lumps,
radii 10-40 mm, released 0.3-0.8 m above a 0.4 x 0.4 m area on the upper part of a 30 degree
0.6 x 0.6 x 0.01 m steel plate, 200 lumps/s, contact damping 300 N s/m), shortened, run
frictionless and with friction on every contact:

* ``frictionless``: the paper's setting;
* ``mu=0.3``, ``mu=0.5``, ``mu=0.7``: mu_s = mu_d = mu, rolling resistance mu_r = 0.1 (in
  the range DEM studies give to rounded rock lumps; below tan 30 deg = 0.58, so a single
  sphere keeps rolling down the beam);
* ``mu=0.7 mu_r=0.7``: rolling resistance above tan 30 deg, standing in for lumps far from
  round: a single lump stops on the beam, later lumps strike the ones at rest.

Stiction velocity 1e-3 m/s, transition velocity 2e-3 m/s (friction.md: creep below 1 mm/s).

The contacts run on the rigid plate (the fast stream solver); the plate forces they record
(force histories of every plate contact) drive the SSSS modal plate one way (10 kHz band, the
reference scene's two sensors), so the sensor signals are those of a plate that does not act
back on the lumps, and the friction force on the plate's surface is not in them (normal
forces only). Per case:

* residence time on the beam: from a lump's first plate contact to its leaving over an edge
  (lumps still on the beam at the end are counted apart);
* plate impacts per lump that touched the beam (contact records with the plate);
* lumps on the beam at the end, and how many of them are at rest (centre speed < 1 cm/s);
* in-band RMS of each sensor over the run and its Welch spectrum;
* how much of the coal / gangue difference survives: the area under the ROC curve (AUC, 0.5 =
  no difference, 1 = separable) of gangue against coal for the peak force of each lump's
  first plate impact and for the RMS of sensor S1 in the 20 ms after it (overlapping later
  impacts included, as a sensor sees them).

Writes ``table.md``, ``cases.csv``, ``lumps_CASE.csv`` and the figures
``friction-stream-lumps.png``, ``friction-stream-stats.png``, ``friction-stream-spectrum.png``
into --out.

    python benchmarks/study_friction_stream.py --out DIR [--quick] [--no-sensors]

--quick: ~100 lumps released over 0.5 s, 1.0 s simulated; the full run ~400 lumps over 2 s,
3 s simulated.
"""

import argparse
import csv
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tailbeam.io.scene_file import loads_scene  # noqa: E402
from tailbeam.solvers.modal_setup.setup import stream_setup  # noqa: E402
from tailbeam.solvers.stream.solver import simulate_stream  # noqa: E402

REST_SPEED = 0.01  # m/s: a lump on the beam slower than this is "at rest"
ON_BEAM_GAP = 1e-3  # m: a lump whose lowest point is within this of the plate is on the beam
FRAME_STEP = 2e-3  # s
WINDOW = 0.02  # s: the sensor window after a lump's first plate impact
HEIGHT = (0.3, 0.8)  # m: the reference scene's release gaps
LOW = (0.02, 0.1)  # m: a low release, where lumps land slowly enough to stop on the beam
CASES = (
    ("frictionless", None, None, HEIGHT),
    ("mu=0.3", 0.3, 0.1, HEIGHT),
    ("mu=0.5", 0.5, 0.1, HEIGHT),
    ("mu=0.7", 0.7, 0.1, HEIGHT),
    ("mu=0.7 mu_r=0.7", 0.7, 0.7, HEIGHT),
    ("low drop, frictionless", None, None, LOW),
    ("low drop, mu=0.7 mu_r=0.7", 0.7, 0.7, LOW),
)

SCENE = """
duration = {duration}
[contact]
damping = 300.0
penetration = 1e-4
{friction}
[plate]
model = "modal"
boundary = "SSSS"
coupling = "one-way"
inclination = 30.0
fmax = 10000.0

[[streams]]
name = "cave"
rate = 200.0
start = 0.0
stop = {stop}
gangue_fraction = 0.3
radius = [0.01, 0.04]
area = [[-0.3, 0.1], [-0.2, 0.2]]
height = [{h0}, {h1}]
seed = {seed}

[[sensors]]
name = "S1"
position = [0.1, 0.0]
sample_rate = 51200.0
bandwidth = 10000.0

[[sensors]]
name = "S2"
position = [-0.15, 0.15]
sample_rate = 51200.0
bandwidth = 10000.0
"""

FRICTION = """[contact.friction]
static = {mu}
dynamic = {mu}
stiction_velocity = 1e-3
transition_velocity = 2e-3
rolling = {mu_r}
"""


def scene_text(mu, mu_r, *, stop, duration, height=HEIGHT, seed=1) -> str:
    """The study's scene file: frictionless when ``mu`` is None."""
    friction = "" if mu is None else FRICTION.format(mu=mu, mu_r=mu_r)
    return SCENE.format(
        duration=duration, stop=stop, seed=seed, friction=friction, h0=height[0], h1=height[1]
    )


def run_case(mu, mu_r, *, stop, duration, height=HEIGHT, sensors=True):
    """(result, wall time s) of one case: contacts on the rigid plate, its plate loads driving
    the modal plate one way."""
    scene = loads_scene(scene_text(mu, mu_r, stop=stop, duration=duration, height=height))
    frames = np.arange(0.0, duration + 0.5 * FRAME_STEP, FRAME_STEP)
    frames = frames[frames <= duration]
    setup = stream_setup(scene) if sensors else None
    start = time.perf_counter()
    result = simulate_stream(
        scene.particles, scene.incline, scene.duration, laws=scene.contacts(), setup=setup,
        sensors=scene.sensors if sensors else (), frames=frames, friction=scene.friction,
    )  # fmt: skip
    return result, time.perf_counter() - start


def lump_table(result) -> list:
    """Per lump: name, label, radius, t_release, first plate touch (s, nan: never), t_leave
    (s, nan: still there), plate impacts, first impact's peak force (N) and time (s), on the
    beam at the end, at rest at the end."""
    parts = result.particles_table()
    imp = result.impacts_table()
    plate = imp["partner"] == "plate"
    last = result.frames.position.shape[0] - 1
    pos, vel = result.frames.position[last], result.frames.velocity[last]
    rows = []
    for i, name in enumerate(parts["name"]):
        mine = np.flatnonzero(plate & (imp["ball"] == name))
        first = mine[np.argmin(imp["t_start"][mine])] if mine.size else None
        r = float(parts["radius"][i])
        on_beam = bool(np.isfinite(pos[i, 2]) and pos[i, 2] - r < ON_BEAM_GAP)
        speed = float(np.linalg.norm(vel[i])) if on_beam else math.nan
        rows.append(
            {
                "name": name,
                "label": parts["label"][i],
                "radius": r,
                "t_release": float(parts["t_release"][i]),
                "t_touch": math.nan if first is None else float(imp["t_start"][first]),
                "t_leave": float(parts["t_leave"][i]),
                "plate_impacts": int(mine.size),
                "first_peak_force": math.nan if first is None else float(imp["peak_force"][first]),
                "on_beam_end": on_beam,
                "at_rest_end": bool(on_beam and speed < REST_SPEED),
            }
        )
    return rows


def auc(coal, gangue) -> float:
    """Area under the ROC curve of gangue against coal (Mann-Whitney U / (n1 n2)); nan if a
    class is empty."""
    from sklearn.metrics import roc_auc_score

    coal, gangue = np.asarray(coal, float), np.asarray(gangue, float)
    coal, gangue = coal[np.isfinite(coal)], gangue[np.isfinite(gangue)]
    if not (coal.size and gangue.size):
        return math.nan
    y = np.r_[np.zeros(coal.size), np.ones(gangue.size)]
    return float(roc_auc_score(y, np.r_[coal, gangue]))


def window_rms(t, a, starts, length=WINDOW) -> np.ndarray:
    """RMS (m/s^2) of the signal a(t) over [s, s + length) for each start s."""
    out = np.full(len(starts), math.nan)
    for k, s in enumerate(starts):
        sel = (t >= s) & (t < s + length)
        if np.isfinite(s) and sel.any():
            out[k] = math.sqrt(float(np.mean(a[sel] ** 2)))
    return out


def summarise(name, result, lumps, wall, duration) -> dict:
    """The case's row of the table."""
    touched = [r for r in lumps if np.isfinite(r["t_touch"])]
    left = [r for r in touched if np.isfinite(r["t_leave"])]
    residence = np.array([r["t_leave"] - r["t_touch"] for r in left])
    on_end = [r for r in lumps if r["on_beam_end"]]
    rest_end = [r for r in on_end if r["at_rest_end"]]
    coal = [r for r in touched if r["label"] == "coal"]
    gangue = [r for r in touched if r["label"] != "coal"]
    row = {
        "case": name,
        "lumps": len(lumps),
        "touched_beam": len(touched),
        "residence_mean_s": float(residence.mean()) if residence.size else math.nan,
        "residence_median_s": float(np.median(residence)) if residence.size else math.nan,
        "plate_impacts_per_lump": float(np.mean([r["plate_impacts"] for r in touched])),
        "on_beam_end": len(on_end),
        "at_rest_end": len(rest_end),
        "fraction_at_rest": len(rest_end) / max(1, len(touched)),
        "auc_peak_force": auc(
            [r["first_peak_force"] for r in coal], [r["first_peak_force"] for r in gangue]
        ),
        "energy_friction_J": float(result.stats.get("energy_friction", 0.0)),
        "wall_s": wall,
    }
    signals = result.sensor_signals
    for sensor, (t, a) in signals.items():
        band = t <= duration
        row[f"{sensor}_rms"] = math.sqrt(float(np.mean(a[band] ** 2)))
    if "S1" in signals:
        t, a = signals["S1"]
        rms = window_rms(t, a, [r["t_touch"] for r in touched])
        lab = np.array([r["label"] == "coal" for r in touched])
        row["auc_S1_window_rms"] = auc(rms[lab], rms[~lab])
    return row


def spectrum(t, a):
    """(f Hz, one-sided PSD (m/s^2)^2/Hz) by Welch's method, 4096-sample segments."""
    from scipy.signal import welch

    fs = 1.0 / float(np.median(np.diff(t)))
    return welch(a, fs=fs, nperseg=min(4096, a.size))


def write_csv(path, rows):
    with Path(path).open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)


def fmt(v) -> str:
    if isinstance(v, float):
        return "n/a" if not math.isfinite(v) else f"{v:.3g}"
    return str(v)


def write_table(path, rows, args):
    cols = [
        ("case", "case"),
        ("lumps", "lumps"),
        ("touched_beam", "touched the beam"),
        ("residence_mean_s", "residence mean (s)"),
        ("residence_median_s", "median (s)"),
        ("plate_impacts_per_lump", "plate impacts per lump"),
        ("on_beam_end", "on the beam at the end"),
        ("at_rest_end", "of them at rest"),
        ("S1_rms", "S1 RMS (m/s²)"),
        ("S2_rms", "S2 RMS (m/s²)"),
        ("auc_peak_force", "AUC first peak force"),
        ("auc_S1_window_rms", "AUC S1 20 ms RMS"),
        ("energy_friction_J", "friction's energy (J)"),
        ("wall_s", "wall (s)"),
    ]
    cols = [c for c in cols if c[0] in rows[0]]
    lines = [
        f"python benchmarks/study_friction_stream.py --out DIR{' --quick' if args.quick else ''}",
        "",
        "| " + " | ".join(c[1] for c in cols) + " |",
        "|" + "---|" * len(cols),
    ]
    lines += ["| " + " | ".join(fmt(r[c[0]]) for c in cols) + " |" for r in rows]
    Path(path).write_text("\n".join(lines) + "\n")


COLOURS = {"coal": "0.15", "gangue": "tab:orange"}


def plot_lumps(path, runs, duration):
    """Plate-frame x of every lump from its first plate contact on against t, one panel per
    case: thin in flight, thick while it touches the plate, a dot at each plate impact, a
    circle where it is at rest."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ncol = min(4, len(runs))
    nrow = math.ceil(len(runs) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(3.6 * ncol, 3.4 * nrow + 0.6), sharey=True,
                             squeeze=False)  # fmt: skip
    for ax, (name, result, lumps) in zip(axes.flat, runs, strict=False):
        fr = result.frames
        imp = result.impacts_table()
        plate = imp["partner"] == "plate"
        radius = np.array([r["radius"] for r in lumps])
        on = fr.position[:, :, 2] - radius[None, :] < ON_BEAM_GAP
        speed = np.linalg.norm(fr.velocity, axis=2)
        for i, r in enumerate(lumps):
            if not np.isfinite(r["t_touch"]):
                continue
            colour = COLOURS.get(r["label"], "tab:orange")
            after = fr.times >= r["t_touch"] - 0.5 * FRAME_STEP
            x = np.where(after, fr.position[:, i, 0], np.nan)
            ax.plot(fr.times, x, color=colour, lw=0.4, alpha=0.6)
            ax.plot(fr.times, np.where(on[:, i], x, np.nan), color=colour, lw=1.8)
            mine = plate & (imp["ball"] == r["name"])
            ax.plot(imp["t_start"][mine], imp["x"][mine], ".", ms=3.0, color=colour)
            rest = on[:, i] & (speed[:, i] < REST_SPEED)
            if rest.any():
                ax.plot(fr.times[rest], fr.position[rest, i, 0], "o", ms=3.0, mfc="none",
                        color="tab:blue", mew=0.6)  # fmt: skip
        ax.set_title(name, fontsize=10)
        ax.set_xlabel("t (s)")
        ax.set_xlim(0.0, duration)
        ax.set_ylim(-0.32, 0.34)
        for edge in (-0.3, 0.3):
            ax.axhline(edge, color="0.5", lw=0.6, ls="--")
        ax.grid(alpha=0.3)
    for ax in axes.flat[len(runs) :]:
        ax.set_visible(False)
    for ax in axes[:, 0]:
        ax.set_ylabel("x along the beam, downhill (m)")
    handles = [
        plt.Line2D([], [], color=COLOURS["coal"], lw=0.5, label="coal (thin: in flight)"),
        plt.Line2D([], [], color=COLOURS["gangue"], lw=0.5, label="sandstone"),
        plt.Line2D([], [], color="0.3", lw=1.8, label="touching the plate"),
        plt.Line2D([], [], color="0.3", ls="none", marker=".", label="plate impact"),
        plt.Line2D(
            [], [], ls="none", marker="o", mfc="none", color="tab:blue", label="at rest (< 1 cm/s)"
        ),  # fmt: skip
        plt.Line2D([], [], color="0.5", ls="--", lw=0.6, label="plate edges"),
    ]
    fig.legend(handles=handles, loc="upper center", ncol=6, frameon=False, fontsize=9)
    fig.tight_layout(rect=(0, 0, 1, 1 - 0.5 / (3.4 * nrow + 0.6)))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_stats(path, rows):
    """The statistics against the case."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = [r["case"].replace(" ", "\n") for r in rows]
    panels = [
        ("residence_mean_s", "mean residence on the beam (s)"),
        ("plate_impacts_per_lump", "plate impacts per lump"),
        ("fraction_at_rest", "lumps at rest at the end\n/ lumps that touched the beam"),
        ("S1_rms", "S1 in-band RMS (m/s²)"),
        ("auc_peak_force", "coal/gangue AUC"),
    ]
    panels = [p for p in panels if p[0] in rows[0]]
    fig, axes = plt.subplots(1, len(panels), figsize=(3.2 * len(panels), 3.6))
    x = np.arange(len(rows))
    for ax, (key, label) in zip(axes, panels, strict=True):
        ax.bar(x, [r[key] for r in rows], color="tab:blue", width=0.6, label="first peak force")
        if key == "auc_peak_force" and "auc_S1_window_rms" in rows[0]:
            ax.plot(x, [r["auc_S1_window_rms"] for r in rows], "o", color="tab:red",
                    label="S1 20 ms RMS")  # fmt: skip
            ax.axhline(0.5, color="0.4", lw=0.8, ls="--")
            ax.set_ylim(0.0, 1.0)
            ax.legend(fontsize=7, loc="lower left")
        ax.set_xticks(x, names, fontsize=7)
        ax.set_title(label, fontsize=9)
        ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_spectrum(path, runs):
    """Welch spectrum of S1 per case."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7.5, 4.2))
    for name, result, _ in runs:
        signals = result.sensor_signals
        if "S1" not in signals:
            continue
        f, p = spectrum(*signals["S1"])
        ax.semilogy(f / 1e3, p, lw=0.9, label=name)
    ax.set_xlabel("frequency (kHz)")
    ax.set_ylabel("S1 PSD ((m/s²)²/Hz)")
    ax.set_xlim(0.0, 10.0)
    ax.set_title("S1 acceleration spectrum (Welch, one-way modal replay, 10 kHz band)", fontsize=10)
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--quick", action="store_true", help="~100 lumps over 0.5 s, 1 s simulated")
    ap.add_argument("--no-sensors", action="store_true", help="rigid plate only, no replay")
    ap.add_argument("--cases", nargs="*", help="names of the cases to run (default: all)")
    args = ap.parse_args(argv)
    args.out.mkdir(parents=True, exist_ok=True)
    stop, duration = (0.5, 1.0) if args.quick else (2.0, 3.0)
    cases = [c for c in CASES if not args.cases or c[0] in args.cases]
    rows, runs = [], []
    for name, mu, mu_r, height in cases:
        print(f"case {name}", file=sys.stderr)
        result, wall = run_case(mu, mu_r, stop=stop, duration=duration, height=height,
                                sensors=not args.no_sensors)  # fmt: skip
        lumps = lump_table(result)
        write_csv(args.out / f"lumps_{name.replace(' ', '_')}.csv", lumps)
        row = summarise(name, result, lumps, wall, duration)
        rows.append(row)
        runs.append((name, result, lumps))
        print("  " + ", ".join(f"{k}={fmt(v)}" for k, v in row.items()), file=sys.stderr)
    write_csv(args.out / "cases.csv", rows)
    write_table(args.out / "table.md", rows, args)
    plot_lumps(args.out / "friction-stream-lumps.png", runs, duration)
    plot_stats(args.out / "friction-stream-stats.png", rows)
    if not args.no_sensors:
        plot_spectrum(args.out / "friction-stream-spectrum.png", runs)
    print((args.out / "table.md").read_text())


if __name__ == "__main__":
    main()
