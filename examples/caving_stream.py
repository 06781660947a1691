"""Coal only or 30 % gangue: one caving stream on the inclined modal tail beam, side by side.

    python examples/caving_stream.py [--full] [--out DIR]

Two streams with the same seed, so the same arrivals, sizes, release points and speeds:
in one every particle is coal, in the other 30 % are sandstone (gangue). They fall onto the
30-degree SSSS plate of ``examples/caving_stream.toml``; the stream solver finds every contact
(ball-ball and ball-plate) on the rigid plate and the plate forces drive the modes to
10 kHz, coupled both ways (docs/streams.md), read by two 51.2 kHz accelerometers.

Quick mode (default): 200 particles over 1 s (2 s simulated, about a minute with the basis
cached); ``--full``: the reference scene (1000 particles over 5 s, 6 s simulated).

Writes ``caving_stream.png`` (sensor S1 side by side; their spectrograms; the impacts over
time, coloured by material, sized by peak force) and ``summary.csv`` (what differs: sensor
RMS and spectral centroid, the median plate-impact peak force of coal and of gangue, counts).
"""

import argparse
import csv
import sys
from pathlib import Path

import numpy as np

import tailbeam
from tailbeam.io.scene_file import loads_scene
from tailbeam.study.features import spectral_centroid

HERE = Path(__file__).resolve().parent
CASES = {"coal only": 0.0, "30 % gangue": 0.3}
RATE = 200.0  # particles per second, as the reference scene


def scene(gangue_fraction: float, n_particles: int, fmax_hz: float = 10000.0):
    """The reference scene with ``n_particles`` (stream n / RATE s, 1 s longer simulated)
    and the modal band ``fmax_hz``."""
    stop = n_particles / RATE
    text = (HERE / "caving_stream.toml").read_text()
    text = text.replace("fmax = 10000.0", f"fmax = {fmax_hz!r}")
    text = text.replace("duration = 6.0 ", f"duration = {stop + 1.0!r} ")
    text = text.replace("stop = 5.0 ", f"stop = {stop!r} ")
    text = text.replace("gangue_fraction = 0.3", f"gangue_fraction = {gangue_fraction!r}")
    return loads_scene(text)


def run(n_particles: int = 200, fmax_hz: float = 10000.0) -> dict:
    """name -> the Result of each case (progress on stderr)."""
    results = {}
    for name, fraction in CASES.items():
        print(f"{name}: {n_particles} particles", file=sys.stderr)
        results[name] = tailbeam.simulate(scene(fraction, n_particles, fmax_hz))
    return results


def summary(results: dict) -> list:
    """One row per case: what differs between them."""
    rows = []
    for name, res in results.items():
        table = res.impacts_table()
        plate = table["partner"] == "plate"
        row = {"case": name, "particles": len(res.particles), "impacts": int(plate.sum()),
               "ball_ball_rows": int((~plate).sum())}  # fmt: skip
        for label in ("coal", "gangue"):
            sel = plate & (table["label"] == label)
            row[f"median_peak_force_{label}_N"] = (
                float(np.median(table["peak_force"][sel])) if sel.any() else float("nan")
            )
        for sensor, out in res.sensor_outputs.items():
            fs = out.chain.sample_rate
            row[f"{sensor}_rms_m_s2"] = float(np.sqrt(np.mean(out.acceleration**2)))
            row[f"{sensor}_centroid_hz"] = float(spectral_centroid(out.acceleration, fs))
        rows.append(row)
    return rows


def visualize(results: dict, out_dir) -> Path:
    """caving_stream.png: S1 side by side, spectrograms, impacts over time by material."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from scipy.signal import spectrogram

    fig, axes = plt.subplots(3, 2, figsize=(13, 10), constrained_layout=True)
    fig.suptitle("The same stream (same seed: arrivals, sizes, release points), coal only or with "
                 "30 % sandstone, on the 30° SSSS modal plate")  # fmt: skip
    forces = np.concatenate([r.impacts_table()["peak_force"] for r in results.values()])
    f_range = (0.5 * max(forces[forces > 0].min(), 1e-3), 2.0 * forces.max())
    top = max(float(np.max(np.abs(r.sensor_outputs["S1"].acceleration))) for r in results.values())
    for col, (name, res) in enumerate(results.items()):
        out = res.sensor_outputs["S1"]
        ax = axes[0, col]
        ax.plot(out.t, out.acceleration, lw=0.3)
        rms = np.sqrt(np.mean(out.acceleration**2))
        ax.set(title=f"{name}: sensor S1 (RMS {rms:.0f} m/s²)", xlabel="time t (s)",
               ylabel="acceleration (m/s²)", ylim=(-1.05 * top, 1.05 * top))  # fmt: skip
        fs = out.chain.sample_rate
        f, t, sxx = spectrogram(out.acceleration, fs=fs, nperseg=1024, noverlap=768)
        band = f <= out.chain.bandwidth_hz
        mesh = axes[1, col].pcolormesh(t, f[band] / 1e3, 10 * np.log10(sxx[band] + 1e-12),
                                       shading="auto", cmap="magma", vmin=-30, vmax=50)  # fmt: skip
        axes[1, col].set(title=f"{name}: S1 spectrogram (1024-sample Hann, 75 % overlap)",
                         xlabel="time t (s)", ylabel="frequency (kHz)")  # fmt: skip
        fig.colorbar(mesh, ax=axes[1, col], label="PSD (dB re 1 (m/s²)²/Hz)")
        table = res.impacts_table()
        ax = axes[2, col]
        for label, colour in (("coal", "0.25"), ("gangue", "tab:red")):
            sel = (table["partner"] == "plate") & (table["label"] == label)
            ax.scatter(table["t_start"][sel], table["peak_force"][sel], s=6, c=colour,
                       label=f"{label} on the plate ({sel.sum()})")  # fmt: skip
        sel = (table["partner"] != "plate") & (table["ball"] < table["partner"])
        ax.scatter(table["t_start"][sel], table["peak_force"][sel], s=4, marker="x",
                   c="tab:blue", label=f"ball-ball contacts ({sel.sum()})")  # fmt: skip
        ax.set(title=f"{name}: every contact's peak force", xlabel="contact start (s)",
               ylabel="peak force (N)", yscale="log", ylim=f_range)  # fmt: skip
        ax.legend(loc="lower right", fontsize=8)
    path = Path(out_dir) / "caving_stream.png"
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(full: bool = False, out="out/caving_stream") -> list:
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    results = run(1000 if full else 200)
    rows = summary(results)
    with (out / "summary.csv").open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    visualize(results, out)
    return rows


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--full", action="store_true", help="the reference scene (1000)")
    parser.add_argument("--out", default="out/caving_stream")
    args = parser.parse_args()
    for row in main(args.full, args.out):
        print(row)
