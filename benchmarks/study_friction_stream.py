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
  round: a single rolling lump decelerates on the beam;
* ``low drop, frictionless`` and ``low drop, mu=0.7 mu_r=0.7``: the same stream released
  20-100 mm above the plate, where lumps land slowly enough to roll and stop on the beam;
* ``low drop, mu=0.7 mu_r=0.7 d=0.01mm``: the same with the IMPACT law's penetration d
  = 0.01 mm (else 0.1 mm), so that its damping acts on the small hops of lumps on the beam
  (with d = 0.1 mm the restitution of a hop tends to 1 and lumps hop on for seconds).

Stiction velocity 1e-3 m/s, transition velocity 2e-3 m/s (friction.md: creep below 1 mm/s).

The contacts run on the rigid plate (the fast stream solver); the plate forces they record
(force histories of every plate contact) drive the SSSS modal plate one way (10 kHz band, the
reference scene's two sensors), so the sensor signals are those of a plate that does not act
back on the lumps, and the friction force on the plate's surface is not in them (normal
forces only). Per case:

* residence time on the beam: from a lump's first plate contact to its leaving over an edge
  (lumps still on the beam at the end are counted apart);
* plate contact records per lump that touched the beam;
* lumps on the beam at the end, how many of them are at rest (centre speed < 1 cm/s) and
  how many asleep (frozen by the fast solver's rest rule, docs/friction.md "Rest and heaps":
  velocity exactly zero), and the lumps frozen at some time (a contact record ending
  ``rest``);
* in-band RMS of each sensor over the run and its Welch spectrum;
* how much of the coal / gangue difference survives: the area under the ROC curve (AUC, 0.5 =
  no difference, 1 = separable) of gangue against coal for the peak force of each lump's
  first plate impact and for the RMS of sensor S1 in the 20 ms after it (overlapping later
  impacts included, as a sensor sees them).

Writes ``table.md``, ``cases.csv``, ``lumps_CASE.csv`` and the figures
``friction-stream-lumps.png``, ``friction-stream-stats.png``, ``friction-stream-spectrum.png``
into --out.

    python benchmarks/study_friction_stream.py --out DIR [--quick] [--stop S --duration S]
        [--no-sensors] [--cases NAME ...] [--replot]

--quick: ~100 lumps released over 0.5 s, 1.0 s simulated; the full run ~400 lumps over 2 s,
3 s simulated; --stop and --duration set the release time and the simulated time (s).
Wall and process CPU time of each case's simulation (the sensor set-up not included).
"""

import argparse
import csv
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from tailbeam.errors import WorkLimitError  # noqa: E402
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
    ("low drop, mu=0.7 mu_r=0.7 d=0.01mm", 0.7, 0.7, LOW),
)
PENETRATION = {"low drop, mu=0.7 mu_r=0.7 d=0.01mm": 1e-5}  # m: IMPACT d, else 1e-4

SCENE = """
duration = {duration}
[contact]
damping = 300.0
penetration = {penetration}
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


def scene_text(mu, mu_r, *, stop, duration, height=HEIGHT, seed=1, penetration=1e-4) -> str:
    """The study's scene file: frictionless when ``mu`` is None; ``penetration``: the IMPACT
    law's d (m)."""
    friction = "" if mu is None else FRICTION.format(mu=mu, mu_r=mu_r)
    return SCENE.format(
        duration=duration, stop=stop, seed=seed, friction=friction, h0=height[0], h1=height[1],
        penetration=penetration,
    )  # fmt: skip


def run_case(mu, mu_r, *, stop, duration, height=HEIGHT, sensors=True, penetration=1e-4):
    """(result, wall time s) of one case: contacts on the rigid plate, its plate loads driving
    the modal plate one way."""
    text = scene_text(mu, mu_r, stop=stop, duration=duration, height=height,
                      penetration=penetration)  # fmt: skip
    scene = loads_scene(text)
    frames = np.arange(0.0, duration + 0.5 * FRAME_STEP, FRAME_STEP)
    frames = frames[frames <= duration]
    setup = stream_setup(scene) if sensors else None
    start, cpu = time.perf_counter(), time.process_time()
    try:
        result = simulate_stream(
            scene.particles, scene.incline, scene.duration, laws=scene.contacts(), setup=setup,
            sensors=scene.sensors if sensors else (), frames=frames, friction=scene.friction,
        )  # fmt: skip
    except WorkLimitError as err:  # (the loads for the replay passed their bound: none kept)
        if not sensors:
            raise
        print(f"  sensor replay left out: {err}; run again without sensors", file=sys.stderr)
        return run_case(mu, mu_r, stop=stop, duration=duration, height=height, sensors=False,
                        penetration=penetration)  # fmt: skip
    return result, (time.perf_counter() - start, time.process_time() - cpu)


def lump_table(result) -> list:
    """Per lump: name, label, radius, t_release, first plate touch (s, nan: never), t_leave
    (s, nan: still there), plate impacts, first impact's peak force (N), on the beam at the
    end, at rest at the end (slower than REST_SPEED), asleep at the end (frozen by the rest
    rule: velocity exactly zero), times frozen (contact records ending ``rest``) and the
    first freeze (s, nan: never)."""
    parts = result.particles_table()
    imp = result.impacts_table()
    plate = imp["partner"] == "plate"
    rest = imp["end"] == "rest"
    last = result.frames.position.shape[0] - 1
    pos, vel = result.frames.position[last], result.frames.velocity[last]
    rows = []
    for i, name in enumerate(parts["name"]):
        mine = np.flatnonzero(plate & (imp["ball"] == name))
        first = mine[np.argmin(imp["t_start"][mine])] if mine.size else None
        r = float(parts["radius"][i])
        on_beam = bool(np.isfinite(pos[i, 2]) and pos[i, 2] - r < ON_BEAM_GAP)
        speed = float(np.linalg.norm(vel[i])) if on_beam else math.nan
        frozen = np.flatnonzero(rest & (imp["ball"] == name))
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
                "asleep_end": bool(on_beam and speed == 0.0),
                "freezes": len(set(np.round(imp["t_end"][frozen], 12))),
                "t_first_rest": float(imp["t_end"][frozen].min()) if frozen.size else math.nan,
            }
        )
    return rows


def sensor_signals(result) -> dict:
    """The result's sensor signals, or none (said on stderr) where their replay would pass
    the plate response's memory bound (long resting contacts: many load nodes)."""
    try:
        return result.sensor_signals
    except WorkLimitError as err:
        print(f"  sensor replay left out: {err}", file=sys.stderr)
        return {}


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
    asleep_end = [r for r in on_end if r["asleep_end"]]
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
        "asleep_end": len(asleep_end),
        "ever_frozen": sum(1 for r in lumps if r["freezes"] > 0),
        "freezes": sum(r["freezes"] for r in lumps),
        "fraction_at_rest": len(rest_end) / max(1, len(touched)),
        "auc_peak_force": auc(
            [r["first_peak_force"] for r in coal], [r["first_peak_force"] for r in gangue]
        ),
        "energy_friction_J": float(result.stats.get("energy_friction", 0.0)),
        "wall_s": wall[0],
        "cpu_s": wall[1],
    }
    signals = sensor_signals(result)
    for sensor, (t, a) in signals.items():
        band = t <= duration
        row[f"{sensor}_rms"] = math.sqrt(float(np.mean(a[band] ** 2)))
    if "S1" in signals:
        t, a = signals["S1"]
        rms = window_rms(t, a, [r["t_touch"] for r in touched])
        lab = np.array([r["label"] == "coal" for r in touched])
        row["auc_S1_window_rms"] = auc(rms[lab], rms[~lab])
    return row


def spectrum(t, a, segment=4096):
    """(f Hz, one-sided PSD (m/s^2)^2/Hz) by Welch's method, ``segment``-sample segments."""
    from scipy.signal import welch

    fs = 1.0 / float(np.median(np.diff(t)))
    return welch(a, fs=fs, nperseg=min(segment, a.size))


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
        ("plate_impacts_per_lump", "plate contact records per lump"),
        ("on_beam_end", "on the beam at the end"),
        ("at_rest_end", "of them at rest"),
        ("asleep_end", "of them asleep"),
        ("ever_frozen", "lumps ever frozen"),
        ("S1_rms", "S1 RMS (m/s²)"),
        ("S2_rms", "S2 RMS (m/s²)"),
        ("auc_peak_force", "AUC first peak force"),
        ("auc_S1_window_rms", "AUC S1 20 ms RMS"),
        ("energy_friction_J", "friction's energy (J)"),
        ("wall_s", "wall (s)"),
        ("cpu_s", "CPU (s)"),
    ]
    cols = [c for c in cols if c[0] in rows[0]]
    lines = [
        "python benchmarks/study_friction_stream.py --out DIR "
        + " ".join(f'"{a}"' if " " in a else a for a in args.argv),
        "",
        "| " + " | ".join(c[1] for c in cols) + " |",
        "|" + "---|" * len(cols),
    ]
    lines += ["| " + " | ".join(fmt(r[c[0]]) for c in cols) + " |" for r in rows]
    Path(path).write_text("\n".join(lines) + "\n")


COLOURS = {"coal": "0.15", "gangue": "tab:orange"}


def case_data(result, lumps) -> dict:
    """What the figures need of a run, as arrays (saved as ``case_CASE.npz``)."""
    imp = result.impacts_table()
    index = {r["name"]: i for i, r in enumerate(lumps)}
    plate = np.flatnonzero(imp["partner"] == "plate")
    data = {
        "times": np.asarray(result.frames.times),
        "position": result.frames.position,
        "speed": np.linalg.norm(result.frames.velocity, axis=2),
        "radius": np.array([r["radius"] for r in lumps]),
        "label": np.array([r["label"] for r in lumps]),
        "t_touch": np.array([r["t_touch"] for r in lumps]),
        "impact_ball": np.array([index[b] for b in imp["ball"][plate]], dtype=int),
        "impact_t": np.asarray(imp["t_start"][plate], float),
        "impact_x": np.asarray(imp["x"][plate], float),
        "t_first_rest": np.array([r["t_first_rest"] for r in lumps]),
    }
    for sensor, (t, a) in sensor_signals(result).items():
        data[f"signal_{sensor}_t"], data[f"signal_{sensor}_a"] = np.asarray(t), np.asarray(a)
    return data


def display(case: str) -> str:
    """The case's name for a reader: ``mu=0.3`` -> ``μ = 0.3, μr = 0.1``."""
    for name, mu, mu_r, height in CASES:
        if name == case and mu is not None:
            d = f", d = {PENETRATION[name] * 1e3:g} mm" if name in PENETRATION else ""
            return ("low drop, " if height == LOW else "") + f"μ = {mu:g}, μr = {mu_r:g}" + d
    return case


def npz_name(case: str) -> str:
    return "case_" + case.replace(" ", "_").replace(",", "") + ".npz"


def plot_lumps(path, runs, duration):
    """Plate-frame x of every lump from its first plate contact on against t, one panel per
    case, downhill pointing down: thin in flight, thick while it touches the plate, a dot at
    each plate impact, blue where it is asleep (frozen by the rest rule: velocity exactly
    zero), a hollow circle where it is on the plate slower than REST_SPEED but integrated."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ncol = min(4, len(runs))
    nrow = math.ceil(len(runs) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(3.6 * ncol, 3.4 * nrow + 0.6 + 0.5 * (ncol < 3)),
                             sharey=True, squeeze=False)  # fmt: skip
    for ax, (name, d) in zip(axes.flat, runs, strict=False):
        _lump_panel(ax, d)
        ax.set_title(display(name), fontsize=10)
        ax.set_xlabel("t (s)")
        ax.set_xlim(0.0, duration)
    for ax in axes.flat[len(runs) :]:
        ax.set_visible(False)
    axes[0, 0].set_ylim(0.34, -0.32)  # downhill down
    for ax in axes[:, 0]:
        ax.set_ylabel("x along the beam (m), downhill down")
    handles = [
        plt.Line2D([], [], color=COLOURS["coal"], lw=0.5, label="coal (thin: in flight)"),
        plt.Line2D([], [], color=COLOURS["gangue"], lw=0.5, label="sandstone"),
        plt.Line2D([], [], color="0.3", lw=1.8, label="touching the plate"),
        plt.Line2D([], [], color="0.3", ls="none", marker=".", label="plate impact"),
        plt.Line2D([], [], color="tab:blue", lw=2.2, label="asleep (frozen at rest)"),
        plt.Line2D(
            [],
            [],
            ls="none",
            marker="o",
            mfc="none",
            color="tab:purple",
            label="on the plate < 1 cm/s, not frozen",
        ),  # fmt: skip
        plt.Line2D([], [], color="0.5", ls="--", lw=0.6, label="upper / lower edge"),
    ]
    per_row = 4 if ncol > 2 else 2
    fig.legend(handles=handles, loc="upper center", ncol=per_row, frameon=False, fontsize=9)
    top = 0.25 * math.ceil(len(handles) / per_row) + 0.1  # inches for the legend
    fig.tight_layout(rect=(0, 0, 1, 1 - top / fig.get_figheight()))
    fig.savefig(path, dpi=110)
    plt.close(fig)


def _lump_panel(ax, d):
    """One case's lumps on ``ax`` (``plot_lumps``)."""
    t, pos, speed = d["times"], d["position"], d["speed"]
    on = pos[:, :, 2] - d["radius"][None, :] < ON_BEAM_GAP
    for i, label in enumerate(d["label"]):
        if not np.isfinite(d["t_touch"][i]):
            continue
        colour = COLOURS.get(str(label), "tab:orange")
        x = np.where(t >= d["t_touch"][i] - 0.5 * FRAME_STEP, pos[:, i, 0], np.nan)
        ax.plot(t, x, color=colour, lw=0.4, alpha=0.6)
        ax.plot(t, np.where(on[:, i], x, np.nan), color=colour, lw=1.8)
        mine = d["impact_ball"] == i
        ax.plot(d["impact_t"][mine], d["impact_x"][mine], ".", ms=3.0, color=colour)
        asleep = on[:, i] & (speed[:, i] == 0.0)
        if asleep.any():
            ax.plot(t, np.where(asleep, x, np.nan), color="tab:blue", lw=2.2, alpha=0.8)
        slow = on[:, i] & (speed[:, i] > 0.0) & (speed[:, i] < REST_SPEED)
        if slow.any():
            ax.plot(t[slow], pos[slow, i, 0], "o", ms=3.0, mfc="none", color="tab:purple",
                    mew=0.6)  # fmt: skip
    for edge in (-0.3, 0.3):
        ax.axhline(edge, color="0.5", lw=0.6, ls="--")
    ax.grid(alpha=0.3)


def _num(row, key) -> float:
    """A table cell as a float (nan where a case has none: no sensor replay)."""
    value = row.get(key)
    return math.nan if value in (None, "") else float(value)


def plot_stats(path, rows):
    """The statistics against the case (low releases in a second colour)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = [display(r["case"]).replace("low drop, ", "low drop\n") for r in rows]
    colour = ["tab:green" if r["case"].startswith("low") else "tab:blue" for r in rows]
    panels = [
        ("residence_mean_s", "mean residence on the beam (s)\nfirst touch to leaving"),
        ("plate_impacts_per_lump", "plate contact records per lump\nthat touched the beam"),
        ("on_beam_end", "lumps on the beam at the end\n(circles: of them at rest)"),
        ("S1_rms", "S1 in-band RMS (m/s²)"),
        ("auc_peak_force", "coal/gangue AUC (0.5: none)\nbars: first peak force"),
    ]
    panels = [p for p in panels if p[0] in rows[0]]
    fig, axes = plt.subplots(1, len(panels), figsize=(3.3 * len(panels), 4.0))
    x = np.arange(len(rows))
    for ax, (key, label) in zip(axes, panels, strict=True):
        ax.bar(x, [_num(r, key) for r in rows], color=colour, width=0.6)
        if key == "on_beam_end":
            ax.plot(x, [_num(r, "at_rest_end") for r in rows], "o", mfc="none", color="k",
                    ms=9, label="< 1 cm/s")  # fmt: skip
            if "asleep_end" in rows[0]:
                ax.plot(x, [_num(r, "asleep_end") for r in rows], "o", color="tab:blue", ms=4,
                        label="asleep")  # fmt: skip
            ax.legend(fontsize=7, loc="upper left", framealpha=0.9)
        if key == "auc_peak_force" and "auc_S1_window_rms" in rows[0]:
            ax.plot(x, [_num(r, "auc_S1_window_rms") for r in rows], "o", color="tab:red",
                    label="S1 RMS, 20 ms after it")  # fmt: skip
            ax.axhline(0.5, color="0.4", lw=0.8, ls="--")
            ax.set_ylim(0.0, 1.0)
            ax.legend(fontsize=7, loc="lower left", framealpha=0.9)
        ax.set_xticks(x, names, fontsize=7, rotation=60, ha="right", rotation_mode="anchor")
        ax.set_title(label, fontsize=9)
        ax.grid(alpha=0.3, axis="y")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_spectrum(path, runs):
    """Welch spectrum of S1 per case (releases from the reference heights), and each friction
    case's spectrum over the frictionless one of the same release heights, in dB."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, (top, bottom) = plt.subplots(2, 1, figsize=(8.0, 6.4), sharex=True,
                                      gridspec_kw={"height_ratios": [3, 2]})  # fmt: skip
    base = {}
    colour = {name: f"C{k}" for k, (name, _) in enumerate(runs)}
    for name, d in runs:
        if "signal_S1_a" not in d:
            continue
        f, p = spectrum(d["signal_S1_t"], d["signal_S1_a"], 1024)
        low = name.startswith("low")
        if "frictionless" in name:
            base[low] = p
        if not low:
            top.semilogy(f / 1e3, p, lw=0.9, label=display(name), color=colour[name])
        if low in base and "frictionless" not in name:
            bottom.plot(f / 1e3, 10 * np.log10(p / base[low]), lw=0.9, ls="--" if low else "-",
                        label=display(name), color=colour[name])  # fmt: skip
    top.set_ylabel("S1 PSD ((m/s²)²/Hz)")
    top.set_title("S1 acceleration, one-way modal replay (10 kHz band), Welch, 50 Hz bins",
                  fontsize=10)  # fmt: skip
    top.grid(alpha=0.3, which="both")
    top.legend(fontsize=8)
    bottom.axhline(0.0, color="0.3", lw=0.8)
    bottom.set_ylabel("over frictionless (dB)")
    bottom.set_title("each case over the frictionless one of its release heights (dashed: low "
                     "drop over low drop)", fontsize=9)  # fmt: skip
    bottom.set_xlabel("frequency (kHz)")
    bottom.set_xlim(0.0, 10.0)
    bottom.grid(alpha=0.3)
    bottom.legend(fontsize=8, ncol=2)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("--quick", action="store_true", help="~100 lumps over 0.5 s, 1 s simulated")
    ap.add_argument("--no-sensors", action="store_true", help="rigid plate only, no replay")
    ap.add_argument("--cases", nargs="*", help="names of the cases to run (default: all)")
    ap.add_argument("--replot", action="store_true", help="figures from the saved cases only")
    ap.add_argument("--stop", type=float, help="release lumps until this time (s)")
    ap.add_argument("--duration", type=float, help="simulated time (s)")
    args = ap.parse_args(argv)
    given = list(sys.argv[1:] if argv is None else argv)
    args.argv = [a for k, a in enumerate(given) if "--out" not in given[max(0, k - 1) : k + 1]]
    args.out.mkdir(parents=True, exist_ok=True)
    stop, duration = (0.5, 1.0) if args.quick else (2.0, 3.0)
    stop, duration = args.stop or stop, args.duration or duration
    cases = [c for c in CASES if not args.cases or c[0] in args.cases]
    if args.replot:
        with (args.out / "cases.csv").open() as fh:
            rows = list(csv.DictReader(fh))
        runs = [(r["case"], dict(np.load(args.out / npz_name(r["case"])))) for r in rows]
        duration = max(float(d["times"][-1]) for _, d in runs)
    else:
        rows, runs = [], []
        for name, mu, mu_r, height in cases:
            print(f"case {name}", file=sys.stderr)
            result, wall = run_case(mu, mu_r, stop=stop, duration=duration, height=height,
                                    sensors=not args.no_sensors,
                                    penetration=PENETRATION.get(name, 1e-4))  # fmt: skip
            lumps = lump_table(result)
            write_csv(args.out / f"lumps_{name.replace(' ', '_').replace(',', '')}.csv", lumps)
            row = summarise(name, result, lumps, wall, duration)
            rows.append(row)
            data = case_data(result, lumps)
            np.savez_compressed(args.out / npz_name(name), **data)
            runs.append((name, data))
            print("  " + ", ".join(f"{k}={fmt(v)}" for k, v in row.items()), file=sys.stderr)
        write_csv(args.out / "cases.csv", rows)
        write_table(args.out / "table.md", rows, args)
    plot_lumps(args.out / "friction-stream-lumps.png", runs, duration)
    plot_stats(args.out / "friction-stream-stats.png", rows)
    if any("signal_S1_a" in d for _, d in runs):
        plot_spectrum(args.out / "friction-stream-spectrum.png", runs)
    if (args.out / "table.md").exists():
        print((args.out / "table.md").read_text())


if __name__ == "__main__":
    main()
