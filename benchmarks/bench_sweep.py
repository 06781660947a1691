"""`tailbeam sweep` on 1 and 2 Dask workers against plain processes: throughput, the share of
dataset writing, and worker memory.

    python benchmarks/bench_sweep.py --out DIR [--quick] [--cases N] [--tail quasi-static]
        [--set KEY=VALUE ...]

Reproduces the speed table of docs/datasets.md ("Speed"). The sweep: N single impacts
(default 200, ``--quick`` 20; half coal, half sandstone; radius log-uniform 10-100 mm,
1-5 m/s, anywhere over |x|, |y| <= 0.25 m) on the SSSS modal plate (modes to 5 kHz, basis
cached before timing), one sensor at 12.8 kHz, 25 ms each. Runs, on the same cases:

1. the baseline, in the same run: the cases in a plain loop in this process (run_case, no
   Dask, no writing); then the same cases split over 1 and over 2 plain loops in fresh
   processes started together (one BLAS thread each, as Dask's workers): the 2-process
   speed-up is what this machine gives the work in parallel, the ceiling of the sweep's
   (shared caches and memory bandwidth);
2. the sweep on a LocalCluster of 1 worker, then of 2 workers (fresh dataset folder each;
   workers started and warmed before the clock starts).

``--tail quasi-static`` runs the cases with the quasi-static tail instead of the default
(``plate.tail = "auto"``: the Ritz tail, 32 pseudo-modes per case). Reports cases/s, the
speed-up over 1 worker, the time spent writing the dataset (Zarr + Parquet + CSV) as a share
of the summed case compute time and of the sweep's wall time, the CPU time of the client
process (the client, the in-process scheduler and the nannies) per case, and each worker's
peak resident memory. The client imports its writing libraries (xarray, zarr, pyarrow) before
the clocks start, as it does the workers: a one-off ~0.3 s per process that would otherwise
be charged to whichever run writes first. Timings on a shared machine are noisy: run it 2-3
times. ``--set`` changes a Dask setting for both clusters (e.g.
``--set distributed.scheduler.worker-saturation=inf``), to measure a choice of
``tailbeam.study.sweep.SCHEDULER_CONFIG`` against the shipped one.

Writes DIR/bench_sweep.csv, DIR/table.md and the two datasets (DIR/dataset_1w, DIR/dataset_2w).
"""

import argparse
import csv
import os
import time
from pathlib import Path

import numpy as np
import pandas as pd

from tailbeam.study.case import run_case, warm_basis
from tailbeam.study.design import expand, parse_sweep
from tailbeam.study.sweep import close_client, connect, run_sweep

BLAS_THREADS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS")


def sweep_spec(n_cases: int, tail: str | None = None):
    per_class = max(1, n_cases // 2)

    def dist(lo, hi, kind="uniform"):
        return {"distribution": kind, "low": lo, "high": hi, "samples": per_class}

    scene = {
        "duration": 0.025,
        "plate": {"model": "modal", "boundary": "SSSS", "fmax": 5000.0},
        "balls": [
            {
                "name": "rock",
                "material": "coal",
                "radius": 0.03,
                "position": [0.0, 0.0, 0.0302],
                "velocity": [0.0, 0.0, -2.0],
            }
        ],
        "sensors": [{"name": "S1", "position": [0.1, 0.15], "sample_rate": 12800.0}],
    }
    if tail is not None:
        scene["plate"]["tail"] = tail
    return parse_sweep(
        {
            "scene": scene,
            "seed": 11,
            "axes": {
                "balls.rock.material": ["coal", "sandstone"],
                "balls.rock.radius": dist(0.01, 0.1, "loguniform"),
                "balls.rock.position[2]": {"follow": "balls.rock.radius", "offset": 0.0002},
                "balls.rock.velocity[2]": dist(-5.0, -1.0),
                "balls.rock.position[0]": dist(-0.25, 0.25),
                "balls.rock.position[1]": dist(-0.25, 0.25),
            },
        }
    )


def _peak_rss_mb() -> float:
    import resource

    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # Linux: kB


def _import_writers() -> None:
    """Load the dataset writers' libraries into this process (not timed, as for the workers)."""
    import dask.array  # noqa: F401 - xarray looks for it when building a Dataset
    import pyarrow.parquet  # noqa: F401
    import xarray  # noqa: F401
    import zarr  # noqa: F401


def baseline(cases) -> dict:
    t0 = time.perf_counter()
    for c in cases:
        run_case(c.toml)
    wall = time.perf_counter() - t0
    return {"run": "plain loop (no Dask)", "workers": 1, "wall_s": wall, "cases": len(cases)}


def _loop_process(tomls, barrier, queue) -> None:
    """One plain loop in its own process (as a Dask worker: one BLAS thread); its clock
    starts when every loop of the run is warm (``barrier``)."""
    np.seterr(all="ignore")
    warm_basis(tomls[0])
    run_case(tomls[0])  # numba and the basis loaded, as the sweeps' workers are
    barrier.wait()
    t0 = time.perf_counter()
    for toml in tomls:
        run_case(toml)
    queue.put((t0, time.perf_counter()))


def plain_processes(cases, n: int) -> dict:
    """The cases split over ``n`` plain loops in ``n`` processes started together (no Dask):
    what the machine gives this work in parallel, the ceiling of the sweeps' speed-up."""
    import multiprocessing

    ctx = multiprocessing.get_context("spawn")
    barrier, queue = ctx.Barrier(n), ctx.Queue()
    before = {k: os.environ.get(k) for k in BLAS_THREADS}
    os.environ.update(dict.fromkeys(BLAS_THREADS, "1"))  # inherited by the children
    try:
        parts = [[c.toml for c in cases[i::n]] for i in range(n)]
        procs = [ctx.Process(target=_loop_process, args=(p, barrier, queue)) for p in parts]
        for p in procs:
            p.start()
        spans = [queue.get() for _ in procs]
        for p in procs:
            p.join()
    finally:
        for k, v in before.items():
            os.environ.pop(k) if v is None else os.environ.__setitem__(k, v)
    wall = max(end for _, end in spans) - min(start for start, _ in spans)
    return {"run": f"plain loops, {n} process(es) at once (no Dask)", "workers": n,
            "wall_s": wall, "cases": len(cases), "plain": True}  # fmt: skip


def dask_run(spec, n_workers: int, out: Path) -> dict:
    cases = expand(spec)
    client = connect(workers=n_workers)
    try:
        # warm every worker: imports, numba cache, basis cache (not timed)
        first = expand(spec)[0]
        client.run(warm_basis, first.toml)
        client.run(run_case, first.toml)
        t0, c0 = time.perf_counter(), time.process_time()
        # the cases as `tailbeam sweep` has them: expanded and validated before the cluster
        # starts (design.expand, ~0.1-0.4 ms per case, not part of the workers' throughput)
        summary = run_sweep(spec, out, client=client, cases=cases)
        wall, client_cpu = time.perf_counter() - t0, time.process_time() - c0
        rss = client.run(_peak_rss_mb)
        limit = client.run(lambda dask_worker: dask_worker.memory_manager.memory_limit)
    finally:
        close_client(client)
    ledger = pd.read_csv(out / "cases.csv")
    compute = float(ledger["wall_time"].sum())
    cpu = float(ledger["cpu_time"].sum())
    return {
        "run": f"sweep, LocalCluster {n_workers} worker(s)",
        "workers": n_workers,
        "wall_s": wall,
        "cases": summary["ok"] + summary["failed"],
        "failed": summary["failed"],
        "compute_s": compute,
        "cpu_s": cpu,
        "write_s": summary["write_time_s"],
        "write_share_of_compute": summary["write_time_s"] / compute,
        "write_share_of_wall": summary["write_time_s"] / wall,
        "client_cpu_ms_per_case": 1e3 * client_cpu / (summary["ok"] + summary["failed"]),
        "peak_worker_rss_mb": max(rss.values()),
        "worker_memory_limit_mb": max(limit.values()) / 2**20,
    }


def main(
    out_dir="out/benchmarks/bench_sweep",
    quick: bool = False,
    n_cases: int | None = None,
    tail: str | None = None,
):
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    n = n_cases or (20 if quick else 200)
    spec = sweep_spec(n, tail)
    cases = expand(spec)
    _import_writers()
    warm_basis(cases[0].toml)
    run_case(cases[0].toml)  # compile/load numba here too
    rows = [baseline(cases), plain_processes(cases, 1), plain_processes(cases, 2)]
    for w in (1, 2):
        target = out_dir / f"dataset_{w}w"
        if target.exists():
            import shutil

            shutil.rmtree(target)
        rows.append(dask_run(spec, w, target))
    for r in rows:
        r["cases_per_s"] = r["cases"] / r["wall_s"]
        if "compute_s" in r:
            # time the workers spent inside cases / the time they had: Dask's overhead shows
            # here; a longer mean case time at more workers shows competition for the cores
            r["mean_case_s"] = r["compute_s"] / r["cases"]
            r["worker_occupancy"] = r["compute_s"] / (r["workers"] * r["wall_s"])
            # share of a case's wall time its worker had a core: < 1 when cores are contended
            r["cpu_share"] = r["cpu_s"] / r["compute_s"]
            # throughput if every worker had its own core (an estimate, not a measurement)
            r["cases_per_s_own_cores"] = (
                r["workers"] * r["worker_occupancy"] / (r["cpu_s"] / r["cases"])
            )
    one = next(r for r in rows if r["workers"] == 1 and "sweep" in r["run"])
    for r in rows:
        r["speedup_vs_1_worker"] = r["cases_per_s"] / one["cases_per_s"]
    plain = {r["workers"]: r["cases_per_s"] for r in rows if r.get("plain")}
    for r in rows:  # the same speed-up for the plain processes: the machine's ceiling
        if r.get("plain"):
            r["speedup_vs_1_worker"] = r["cases_per_s"] / plain[1]
    keys = list(dict.fromkeys(k for r in rows[::-1] for k in r))  # the sweep rows' order first
    with (out_dir / "bench_sweep.csv").open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys)
        w.writeheader()
        w.writerows(rows)
    _table(rows, out_dir / "table.md", n)
    return rows


def _table(rows, path: Path, n: int) -> None:
    cores = len(os.sched_getaffinity(0))
    lines = [
        f"{n} single-impact cases (modal plate, cached basis), {cores} cores, load average "
        f"{os.getloadavg()[0]:.1f} at the end (a shared machine: other work competes).",
        "",
        "| run | cases/s | speed-up vs 1 worker (plain processes: vs 1 process) "
        "| mean case time (s) | CPU share of case time "
        "| worker occupancy | cases/s if each worker had a core (estimate) | writing / compute "
        "| writing / wall | client CPU per case (ms) | peak worker RSS (MB) "
        "| worker memory limit (MB) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        share = f"{r['write_share_of_compute']:.1%}" if "write_s" in r else "-"
        share_wall = f"{r['write_share_of_wall']:.1%}" if "write_s" in r else "-"
        client = f"{r['client_cpu_ms_per_case']:.1f}" if "write_s" in r else "-"
        rss = f"{r['peak_worker_rss_mb']:.0f}" if "peak_worker_rss_mb" in r else "-"
        lim = f"{r['worker_memory_limit_mb']:.0f}" if "worker_memory_limit_mb" in r else "-"
        case = f"{r['mean_case_s']:.3f}" if "mean_case_s" in r else "-"
        occ = f"{r['worker_occupancy']:.0%}" if "worker_occupancy" in r else "-"
        cpu = f"{r['cpu_share']:.0%}" if "cpu_share" in r else "-"
        own = f"{r['cases_per_s_own_cores']:.2f}" if "cpu_share" in r else "-"
        lines.append(
            f"| {r['run']} | {r['cases_per_s']:.2f} | {r['speedup_vs_1_worker']:.2f} | {case} "
            f"| {cpu} | {occ} | {own} | {share} | {share_wall} | {client} | {rss} | {lim} |"
        )
    path.write_text("\n".join(lines) + "\n")
    print(path.read_text())


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="output folder")
    parser.add_argument("--quick", action="store_true", help="20 cases")
    parser.add_argument("--cases", type=int, default=None)
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    parser.add_argument(
        "--tail",
        choices=("auto", "quasi-static", "ritz"),
        default=None,
        help="plate.tail of the cases (default: the scene default, auto)",
    )
    args = parser.parse_args()
    np.seterr(all="ignore")
    import dask
    import yaml

    changes = {k: yaml.safe_load(v) for k, v in (item.split("=", 1) for item in args.set)}
    with dask.config.set(changes):
        main(args.out, quick=args.quick, n_cases=args.cases, tail=args.tail)
