"""`tailbeam import` on one hour of 3-channel 25.6 kHz recording: wall time and peak memory.

Writes a synthetic 16-bit WAV file (noise plus a decaying two-mode ring every 0.5 s, written
block by block with the standard library's ``wave``) and its labels file into DIR, then runs
the import in a fresh process per configuration (the whole file as one case; 10 s windows;
10 s windows resampled to 20 kHz; a 0.1 s window per impact) and reports each run's wall
time, CPU time and peak resident memory (``resource.getrusage``), beside the size of the record in
memory (float32), which a whole-file read would need at least. Tables: DIR/table.md and
DIR/table.csv.

    python benchmarks/bench_import.py --out DIR [--minutes M]
"""

import argparse
import csv
import subprocess
import sys
import time
import wave
from pathlib import Path

import numpy as np

FS = 25600
CHANNELS = 3
BLOCK_S = 10
FULL_SCALE_G = 16.0  # the recorder's range: int16 full scale is 16 g
RUN = """
import resource, sys
from tailbeam.cli.main import main
code = main(sys.argv[1:])
use = resource.getrusage(resource.RUSAGE_SELF)
print("PEAK_RSS_KB", use.ru_maxrss, use.ru_utime + use.ru_stime, file=sys.stderr)
sys.exit(code)
"""


def _block(rng, k0: int, n: int) -> np.ndarray:
    t = (k0 + np.arange(n)) / FS
    x = 0.002 * rng.standard_normal((n, CHANNELS))  # g
    since = np.mod(t, 0.5)  # an impact every 0.5 s
    ring = np.exp(-since * 200) * (
        np.sin(2 * np.pi * 900 * since) + 0.4 * np.sin(2 * np.pi * 3100 * since)
    )
    x += ring[:, None] * np.array([1.0, 0.6, 0.3])
    return np.round(x / FULL_SCALE_G * 32767).astype("<i2")


def write_recording(folder: Path, minutes: float) -> Path:
    path = folder / "hour.wav"
    n_total = int(minutes * 60 * FS)
    rng = np.random.default_rng(0)
    with wave.open(str(path), "wb") as w:
        w.setnchannels(CHANNELS)
        w.setsampwidth(2)
        w.setframerate(FS)
        for k0 in range(0, n_total, BLOCK_S * FS):
            w.writeframes(_block(rng, k0, min(BLOCK_S * FS, n_total - k0)).tobytes())
    (folder / "labels.csv").write_text(
        f"file,label,unit,full_scale\n{path.name},coal,g,{FULL_SCALE_G}\n"
    )
    return path


CONFIGS = {
    "whole file, one case": [],
    "10 s windows": ["--cut", "fixed", "--length", "10"],
    "10 s windows, resampled to 20 kHz": [
        "--cut",
        "fixed",
        "--length",
        "10",
        "--sample-rate",
        "20000",
    ],
    "0.1 s window per impact": ["--cut", "impacts", "--length", "0.1"],
}


def run(folder: Path, name: str, extra: list) -> dict:
    out = folder / ("ds-" + "".join(c if c.isalnum() else "-" for c in name))
    argv = ["import", str(folder / "hour.wav"), "--labels", str(folder / "labels.csv"),
            "--out", str(out), "--quiet", *extra]  # fmt: skip
    start = time.perf_counter()
    proc = subprocess.run([sys.executable, "-c", RUN, *argv], capture_output=True, text=True)
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        raise SystemExit(f"{name}: {proc.stderr.strip()}")
    line = next(x for x in proc.stderr.splitlines() if x.startswith("PEAK_RSS_KB"))
    rss, cpu = int(line.split()[1]), float(line.split()[2])
    print(proc.stdout.strip().splitlines()[-1], file=sys.stderr)
    return {"configuration": name, "options": " ".join(extra) or "-", "wall_s": round(wall, 1),
            "cpu_s": round(cpu, 1), "peak_rss_mb": round(rss / 1024)}  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--minutes", type=float, default=60.0, help="length of the record")
    args = parser.parse_args()
    folder = Path(args.out)
    folder.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    write_recording(folder, args.minutes)
    print(f"wrote {args.minutes:g} min in {time.perf_counter() - t0:.0f} s", file=sys.stderr)
    rows = [run(folder, name, extra) for name, extra in CONFIGS.items()]
    in_memory = args.minutes * 60 * FS * CHANNELS * 4 / 2**20
    with open(folder / "table.csv", "w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]))
        writer.writeheader()
        writer.writerows(rows)
    lines = [
        f"{args.minutes:g} min, {CHANNELS} channels, {FS} Hz, int16 WAV; the record as float32: "
        f"{in_memory:.0f} MB",
        "",
        "| configuration | options | wall time, s | CPU time, s | peak RSS, MB |",
        "|---|---|---|---|---|",
        *(f"| {r['configuration']} | `{r['options']}` | {r['wall_s']} | {r['cpu_s']} | "
          f"{r['peak_rss_mb']} |"
          for r in rows),
    ]  # fmt: skip
    (folder / "table.md").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
