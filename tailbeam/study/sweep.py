"""Running a sweep's cases on Dask and recording them in the dataset.

Each case is one Dask task (``tailbeam.study.case.run_case``). By default a local cluster is
started (``dask.distributed.LocalCluster``: one single-threaded worker process per core, on
127.0.0.1, no dashboard); given a scheduler address, the cases go to that cluster instead; its
workers need tailbeam installed and, to share modal bases, one TAILBEAM_CACHE_DIR.

Before the cases, one task per distinct modal basis (``case.basis_signature``) fills the basis
cache and the cases of that basis wait for it, so a sweep over plates computes each basis once.
Finished cases are gathered in batches (one request per batch of results, at most every
``GATHER_INTERVAL_S``, not one per case) and written in large batches (``DatasetStore.record``):
a batch is written after ``FLUSH_SECONDS``, or once it holds ``FLUSH_BYTES`` of signals or
``FLUSH_CASES`` cases, so the client holds a bounded amount of results and a crash loses at most
one batch. Running the same sweep again skips the cases already stored and retries the failed
ones.
"""

import asyncio
import os
import time
import uuid

from tailbeam.errors import InputError
from tailbeam.io.scene_file import loads_scene
from tailbeam.progress import note, task
from tailbeam.study.case import band_estimate, run_case, validity, warm_basis
from tailbeam.study.dataset import DatasetStore
from tailbeam.study.design import expand

FLUSH_SECONDS = 30.0  # write a batch after this long (s) ...
FLUSH_BYTES = 64 << 20  # ... or once its signals take this many bytes ...
FLUSH_CASES = 5000  # ... or once it holds this many cases, whichever comes first
# collect finished results at most this often (s): each collection is a round trip client ->
# scheduler -> workers and back on the client process's event loop, which shares the cores with
# the workers (every 0.1 s, a collection held ~1-2 results at 10-20 cases/s). Near the end of
# a sweep the client waits only until the last cases are done (_pause).
GATHER_INTERVAL_S = 0.5
# worker processes of a local cluster: Dask's defaults minus two costs that weigh on cases of a
# few tens of ms: MALLOC_TRIM_THRESHOLD_=65536 (setting it turns off glibc's dynamic mmap
# threshold, so large numpy temporaries are mmapped and unmapped each time: cases ~10 % slower,
# measured) and the statistical profiler (it samples the task thread every 10 ms; not
# measured on its own). Memory stays bounded by each worker's memory_limit (the worker pauses
# at 80 % of it, the nanny restarts it past 95 %).
WORKER_CONFIG = {
    "distributed.worker.profile.enabled": False,
    "distributed.nanny.pre-spawn-environ": {
        "OMP_NUM_THREADS": 1,
        "MKL_NUM_THREADS": 1,
        "OPENBLAS_NUM_THREADS": 1,
    },
}
# the local scheduler and nannies, which share the cores with the workers:
# - the system monitor (CPU, memory, disk and network counters for the dashboard, which a sweep
#   does not start) every 2 s instead of every 0.5 s, without disk;
# - the event-loop health tick (it only warns when a loop was blocked for seconds) every 0.2 s
#   instead of 20 ms, and the nannies' check of their worker's memory every 0.5 s instead of
#   0.1 s (a case takes ~0.4 GB of a limit of GBs). Together these periodic callbacks took
#   ~10 % of the client process's event-loop CPU (yappi), which competes with the workers.
# Dask's queuing stays on (worker-saturation 1.1): sending every case at once
# (worker-saturation inf) made 1 worker faster and 2 workers slower (docs/datasets.md).
SCHEDULER_CONFIG = {
    "distributed.admin.system-monitor.interval": "2s",
    "distributed.admin.system-monitor.disk": False,
    "distributed.admin.tick.interval": "200ms",
    "distributed.worker.memory.monitor-interval": "500ms",
}


def default_workers() -> int:
    """One worker per core the process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def local_cluster(n_workers: int):
    """A dask.distributed LocalCluster of ``n_workers`` single-threaded processes on
    127.0.0.1, without dashboard, with WORKER_CONFIG and SCHEDULER_CONFIG; the scheduler's
    HTTP routes take a free port (not 8787, so sweeps and other Dask users on one machine do
    not collide). The scheduler listens on TCP (``cluster.scheduler_address``, for the
    workers) and in-process (``inproc://``, for a client in this process: in_process_client)."""
    import logging

    import dask
    from dask.distributed import LocalCluster

    # the scheduler is built here, in this process; the nannies pass the config to the workers
    with dask.config.set({**SCHEDULER_CONFIG, **WORKER_CONFIG}):
        return LocalCluster(
            n_workers=n_workers,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
            scheduler_kwargs={
                "dashboard_address": "127.0.0.1:0",
                # the first listener is the address the workers get
                "protocol": ["tcp", "inproc"],
                "host": ["127.0.0.1", None],
                "port": [0, None],
            },
            silence_logs=logging.ERROR,
        )


def connect(workers: int | None = None, scheduler: str | None = None):
    """A dask.distributed Client: to ``scheduler`` if given, else to a new local_cluster of
    ``workers`` processes (default: one per core). Close it with close_client."""
    from dask.distributed import Client

    if scheduler:
        try:
            return Client(scheduler, timeout="10s")
        except (OSError, TimeoutError) as err:
            raise InputError("--scheduler", f"cannot reach {scheduler!r}: {err}") from None
    n = workers or default_workers()
    if workers is None:
        note(f"sweep: {n} local Dask workers, one per core (--workers N to change)")
    cluster = local_cluster(n)
    client = in_process_client(cluster)
    client._tailbeam_cluster = cluster  # closed together in close_client
    return client


def in_process_client(cluster):
    """A Client of a local_cluster on the scheduler's event loop, through its ``inproc://``
    listener: messages between client and scheduler (task reports, gathers, releases) pass
    as Python objects, without TCP or serialisation (the client process's CPU per task:
    2.4-3.1 ms through TCP, 2.2 ms in-process, measured on 200 tasks of 50 ms)."""
    from dask.distributed import Client

    address = next(
        lst.contact_address
        for lst in cluster.scheduler.listeners
        if lst.contact_address.startswith("inproc://")
    )
    return Client(address, loop=cluster.loop)


def close_client(client) -> None:
    """Close the client, and its local cluster if connect() started one."""
    cluster = getattr(client, "_tailbeam_cluster", None)
    client.close()
    if cluster is not None:
        cluster.close()


def plan(spec, out_dir, cases=None):
    """(all cases, cases still to run, store): the finished cases of out_dir are skipped.
    ``cases``: expand(spec) if already computed."""
    cases = expand(spec) if cases is None else cases
    store = DatasetStore(out_dir, spec.text, spec.band_accuracy)
    done = store.done()
    todo, seen = [], set(done)
    for c in cases:
        if c.hash not in seen:  # identical scenes (e.g. repeats without noise) run once
            seen.add(c.hash)
            todo.append(c)
    return cases, todo, store


def _submit(client, todo: list) -> dict:
    """Submit the basis warm-up tasks and the case tasks (one task per case, one
    ``client.map`` call per basis); future -> case."""
    groups = {}  # basis signature -> [case]
    for c in todo:
        groups.setdefault(c.basis, []).append(c)
    futures = {}
    for members in groups.values():
        _band_note(members[0].toml)
        warm = client.submit(warm_basis, members[0].toml, key=f"tailbeam-basis-{uuid.uuid4().hex}")
        n = len(members)
        keys = [f"tailbeam-case-{c.hash[:16]}-{uuid.uuid4().hex[:8]}" for c in members]
        tomls = [c.toml for c in members]
        for fut, case in zip(
            client.map(run_case, tomls, [warm] * n, key=keys), members, strict=True
        ):
            futures[fut] = case
    return futures


def _band_note(toml: str) -> None:
    """The stream band check (``tailbeam.solvers.modal_setup.band.check_stream_band``) of a
    basis group's first case, said once: the cases themselves run quietly."""
    from tailbeam.solvers.modal_setup.band import check_stream_band, stream_band

    scene = loads_scene(toml)
    if scene.needs_stream_solver and scene.plate_model == "modal":
        warning = check_stream_band(scene, stream_band(scene))
        if warning:
            note(f"{warning} [first case of its basis]")


def _invalid_note(case, result, accuracy: float, count: int) -> None:
    """One line on stderr for a case flagged invalid (``valid`` False in cases.csv)."""
    shown = ", ".join(f"{k} = {v!r}" for k, v in case.params.items())
    reason = validity(result, accuracy)["invalid_reason"]
    note(f"case {case.hash[:12]} ({shown}) flagged invalid ({count} so far): {reason}")


def invalid_up_front(cases, accuracy: float) -> list:
    """(number from 1, case, band columns) of the cases whose band check, run before any
    basis (``case.band_estimate``), exceeds ``accuracy``."""
    out = []
    with task(f"band check of {len(cases)} cases", total=len(cases), unit="cases") as bar:
        for number, case in enumerate(cases, start=1):
            columns = band_estimate(loads_scene(case.toml))
            if not validity(columns, accuracy)["valid"]:
                out.append((number, case, columns))
            bar.update(1)
    return out


def _pause(futures: dict, rate: float) -> None:
    """Wait before the next gather: GATHER_INTERVAL_S while the cases left take longer than
    two intervals at ``rate`` (cases/s so far); near the end, until every case left is done
    (at most GATHER_INTERVAL_S), so the sweep ends with its last case, not with a wait."""
    from dask.distributed import wait

    if len(futures) > 2 * GATHER_INTERVAL_S * rate:
        time.sleep(GATHER_INTERVAL_S)
        return
    try:  # a few futures (about twice what finishes per interval): one waiter each
        wait(list(futures), timeout=GATHER_INTERVAL_S)
    except (TimeoutError, asyncio.TimeoutError):  # distinct classes before Python 3.11
        pass


def _results_of(client, done: list) -> list:
    """Results of finished futures, gathered in one request; a failed record for each task
    that itself died (e.g. a lost worker)."""
    ok = [f for f in done if f.status == "finished"]
    results = dict(zip(ok, client.gather(ok), strict=True)) if ok else {}
    return [results[f] if f in results else _failed_task(f) for f in done]


def _failed_task(fut) -> dict:
    err = fut.exception()
    message = f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}"
    return {
        "status": "failed",
        "error": f"task {fut.status}: {message}",
        "signals": {},
        "impacts": [],
        "n_coal_impacts": 0,
        "n_gangue_impacts": 0,
        "wall_time": float("nan"),
        "cpu_time": float("nan"),
    }


def run_sweep(spec, out_dir, *, workers=None, scheduler=None, client=None, cases=None) -> dict:
    """Run the cases of ``spec`` not yet finished in ``out_dir``; returns counts and times.

    ``client``: an existing dask.distributed Client to use (then workers/scheduler are
    ignored and the client is left open). ``cases``: ``expand(spec)`` if the caller has it."""
    from dask.distributed import as_completed

    cases, todo, store = plan(spec, out_dir, cases)
    summary = {"cases": len(cases), "skipped": len(cases) - len(todo), "ok": 0, "failed": 0,
               "invalid": 0}  # fmt: skip
    if not todo:
        note(f"sweep: all {len(cases)} cases already done in {out_dir}")
        return summary
    first = loads_scene(todo[0].toml)
    n_time = int(first.duration * first.sensors[0].sample_rate + 1e-9) + 1
    mb = len(todo) * len(first.sensors) * n_time * 4 / 1e6
    note(
        f"sweep: {len(cases)} cases, {summary['skipped']} already done, {len(todo)} to run "
        f"(~{mb:.3g} MB of float32 signals to write)"
    )
    own = client is None
    client = client or connect(workers, scheduler)
    t0 = time.perf_counter()
    write_s = 0.0
    try:
        futures = _submit(client, todo)
        batch, started = _Batch(), time.monotonic()
        with task(f"sweep of {len(todo)} cases", total=len(todo), unit="cases") as bar:
            for done in as_completed(list(futures)).batches():
                for fut, result in zip(done, _results_of(client, done), strict=True):
                    case = futures.pop(fut)
                    summary[result["status"]] += 1
                    if result["status"] != "ok":
                        bar.set_postfix(f"{summary['failed']} failed")
                        note(f"case {case.hash[:12]} failed ({summary['failed']} so far): "
                             f"{result['error']}")  # fmt: skip
                    elif not validity(result, spec.band_accuracy)["valid"]:
                        summary["invalid"] += 1
                        _invalid_note(case, result, spec.band_accuracy, summary["invalid"])
                    batch.add(case, result)
                bar.update(len(done))
                if batch.full():
                    write_s += batch.flush(store)
                if futures:  # let results accumulate: fewer, larger gathers
                    ran = summary["ok"] + summary["failed"]
                    _pause(futures, ran / (time.monotonic() - started))
            write_s += batch.flush(store)
    finally:
        if own:
            close_client(client)
    summary["wall_time_s"] = time.perf_counter() - t0
    summary["write_time_s"] = write_s
    return summary


class _Batch:
    """Finished cases waiting to be written, with the FLUSH_* bounds."""

    def __init__(self):
        self.items, self.bytes, self.start = [], 0, time.monotonic()

    def add(self, case, result) -> None:
        self.items.append((case, result))
        self.bytes += sum(a.nbytes for a in result["signals"].values())

    def full(self) -> bool:
        """True when the batch should be written."""
        return (
            len(self.items) >= FLUSH_CASES
            or self.bytes >= FLUSH_BYTES
            or time.monotonic() - self.start > FLUSH_SECONDS
        )

    def flush(self, store) -> float:
        """Record the batch and empty it; returns the time it took (s)."""
        t = time.perf_counter()
        if self.items:
            store.record(self.items)
        self.items, self.bytes, self.start = [], 0, time.monotonic()
        return time.perf_counter() - t
