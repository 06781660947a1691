"""Where the sweep's client process spends its CPU: per thread, per case.

    python benchmarks/profile_sweep_client.py [--workers 2] [--cases 200] [--set KEY=VALUE ...]

Runs the cases of ``bench_sweep.py`` (same spec and seed) on a LocalCluster of ``--workers``
workers as ``tailbeam sweep`` does (``connect``, ``run_sweep``; workers warmed before the
clock) and prints the CPU time each thread of this process took during the sweep, per case,
from Linux's per-thread counters (/proc/self/task/*/stat, 10 ms ticks): "IO loop" is Dask's
event loop, shared by the client, the in-process scheduler and the nannies; "MainThread" is
``run_sweep`` (gathering, progress, writing); "zarr_io" is Zarr's writer. The process total
(``time.process_time``) is what ``bench_sweep.py`` reports as client CPU per case. Linux only.
"""

import argparse
import os
import shutil
import tempfile
import threading
import time
from pathlib import Path

import numpy as np
from bench_sweep import _import_writers, sweep_spec

from tailbeam.study.case import run_case, warm_basis
from tailbeam.study.design import expand
from tailbeam.study.sweep import close_client, connect, run_sweep


def thread_cpu() -> dict:
    """CPU time (s) of each live thread of this process: native thread id -> seconds."""
    tick = os.sysconf("SC_CLK_TCK")
    out = {}
    for tid in os.listdir("/proc/self/task"):
        try:
            stat = Path(f"/proc/self/task/{tid}/stat").read_text()
        except OSError:  # the thread ended
            continue
        fields = stat[stat.rindex(")") + 2 :].split()
        out[int(tid)] = (int(fields[11]) + int(fields[12])) / tick  # utime + stime
    return out


def main(workers: int = 2, n_cases: int = 200) -> dict:
    spec = sweep_spec(n_cases)
    cases = expand(spec)
    _import_writers()
    out = Path(tempfile.mkdtemp(prefix="profile_sweep_client-"))
    client = connect(workers=workers)
    try:
        client.run(warm_basis, cases[0].toml)
        client.run(run_case, cases[0].toml)
        before, c0, t0 = thread_cpu(), time.process_time(), time.perf_counter()
        summary = run_sweep(spec, out / "dataset", client=client, cases=cases)
        after, cpu, wall = thread_cpu(), time.process_time() - c0, time.perf_counter() - t0
        names = {t.native_id: t.name for t in threading.enumerate()}
    finally:
        close_client(client)
        shutil.rmtree(out)
    n = summary["ok"] + summary["failed"]
    per_thread = {}
    for tid, s in after.items():
        name = names.get(tid, f"thread {tid} (ended or not Python)")
        per_thread[name] = per_thread.get(name, 0.0) + 1e3 * (s - before.get(tid, 0.0)) / n
    print(f"{workers} worker(s), {n} cases in {wall:.2f} s ({n / wall:.2f} cases/s)")
    print(f"client process CPU: {1e3 * cpu / n:.2f} ms per case, of which")
    for name, ms in sorted(per_thread.items(), key=lambda kv: -kv[1]):
        if ms > 0:
            print(f"  {name}: {ms:.2f} ms per case")
    return per_thread


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cases", type=int, default=200)
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    args = parser.parse_args()
    np.seterr(all="ignore")
    import dask
    import yaml

    changes = {k: yaml.safe_load(v) for k, v in (item.split("=", 1) for item in args.set)}
    with dask.config.set(changes):
        main(args.workers, args.cases)
