"""Running a sweep's cases on Dask and recording them in the dataset.

Each case is one Dask task (``tailbeam.study.case.run_case``). By default a local cluster is
started (``dask.distributed.LocalCluster``: one single-threaded worker process per core, on
127.0.0.1, no dashboard); given a scheduler address, the cases go to that cluster instead; its
workers need tailbeam installed and, to share modal bases, one TAILBEAM_CACHE_DIR.

Before the cases, one task per distinct modal basis (``case.basis_signature``) fills the basis
cache and the cases of that basis wait for it, so a sweep over plates computes each basis once.
Results are written in batches as they arrive (``DatasetStore.record``); running the same sweep
again skips the cases already stored and retries the failed ones.
"""

import os
import time
import uuid

from tailbeam.errors import InputError
from tailbeam.progress import note, task
from tailbeam.scene_file import loads_scene
from tailbeam.study.case import basis_signature, run_case, warm_basis
from tailbeam.study.dataset import DatasetStore
from tailbeam.study.design import expand

FLUSH_CASES = 50  # write a batch after this many results ...
FLUSH_SECONDS = 30.0  # ... or after this long (s), whichever comes first


def default_workers() -> int:
    """One worker per core the process may use."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - not Linux
        return os.cpu_count() or 1


def local_cluster(n_workers: int):
    """A dask.distributed LocalCluster of ``n_workers`` single-threaded processes on
    127.0.0.1, without dashboard; the scheduler's HTTP routes take a free port (not 8787,
    so sweeps and other Dask users on one machine do not collide)."""
    import logging

    from dask.distributed import LocalCluster

    return LocalCluster(
        n_workers=n_workers,
        threads_per_worker=1,
        processes=True,
        host="127.0.0.1",
        dashboard_address=None,
        scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},
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
    client = Client(cluster)
    client._tailbeam_cluster = cluster  # closed together in close_client
    return client


def close_client(client) -> None:
    """Close the client, and its local cluster if connect() started one."""
    cluster = getattr(client, "_tailbeam_cluster", None)
    client.close()
    if cluster is not None:
        cluster.close()


def plan(spec, out_dir):
    """(all cases, cases still to run, store): the finished cases of out_dir are skipped."""
    cases = expand(spec)
    store = DatasetStore(out_dir, spec.text)
    done = store.done()
    todo, seen = [], set(done)
    for c in cases:
        if c.hash not in seen:  # identical scenes (e.g. repeats without noise) run once
            seen.add(c.hash)
            todo.append(c)
    return cases, todo, store


def _submit(client, todo: list, coal: tuple) -> dict:
    """Submit the basis warm-up tasks and the case tasks; future -> (case, scene)."""
    scenes = {c.hash: loads_scene(c.toml) for c in todo}
    warm = {}
    for c in todo:
        sig = basis_signature(scenes[c.hash])
        if sig not in warm:
            warm[sig] = client.submit(warm_basis, c.toml, key=f"tailbeam-basis-{uuid.uuid4().hex}")
    futures = {}
    for c in todo:
        dep = warm[basis_signature(scenes[c.hash])]
        key = f"tailbeam-case-{c.hash[:16]}-{uuid.uuid4().hex[:8]}"
        fut = client.submit(run_case, c.toml, coal, dep, key=key, pure=False)
        futures[fut] = (c, scenes[c.hash])
    return futures


def _result_of(fut) -> dict:
    """The case result, or a failed record when the task itself died (e.g. a lost worker)."""
    if fut.status == "finished":
        return fut.result()
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


def run_sweep(spec, out_dir, *, workers=None, scheduler=None, client=None) -> dict:
    """Run the cases of ``spec`` not yet finished in ``out_dir``; returns counts and times.

    ``client``: an existing dask.distributed Client to use (then workers/scheduler are
    ignored and the client is left open)."""
    from dask.distributed import as_completed

    cases, todo, store = plan(spec, out_dir)
    summary = {"cases": len(cases), "skipped": len(cases) - len(todo), "ok": 0, "failed": 0}
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
        futures = _submit(client, todo, spec.coal)
        batch, last = [], time.monotonic()
        with task(f"sweep of {len(todo)} cases", total=len(todo), unit="cases") as bar:
            for fut in as_completed(list(futures)):
                case, scene = futures.pop(fut)
                result = _result_of(fut)
                fut.release()
                summary[result["status"]] += 1
                if result["status"] != "ok":
                    bar.set_postfix(f"{summary['failed']} failed")
                    note(f"case {case.hash[:12]} failed ({summary['failed']} so far): "
                         f"{result['error']}")  # fmt: skip
                batch.append((case, result, scene))
                bar.update(1)
                if len(batch) >= FLUSH_CASES or time.monotonic() - last > FLUSH_SECONDS:
                    write_s += _flush(store, batch)
                    batch, last = [], time.monotonic()
            write_s += _flush(store, batch)
    finally:
        if own:
            close_client(client)
    summary["wall_time_s"] = time.perf_counter() - t0
    summary["write_time_s"] = write_s
    return summary


def _flush(store, batch) -> float:
    """Record a batch; returns the time it took (s)."""
    if not batch:
        return 0.0
    t = time.perf_counter()
    store.record(batch)
    return time.perf_counter() - t
