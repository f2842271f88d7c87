"""Running a sweep's chunks on Dask (``dask.distributed``): one task per chunk, results written as they come.

By default the chunks run on a :class:`distributed.LocalCluster` started for
the sweep and closed after it: one worker process per core, one thread each,
listening on 127.0.0.1 only (``workers=0``: in this process, without Dask), with Numba held to one thread per process
(``NUMBA_NUM_THREADS=1``) so that the processes do not oversubscribe the
cores. With ``device="cuda"`` the cluster has one worker process per GPU
instead, each seeing that GPU alone (:func:`gpu_workers`, :func:`local_cluster`'s
``gpus``). ``client=`` runs them on any existing cluster instead (a
``LocalCluster``, ``dask scheduler`` + ``dask worker`` processes on other
machines, dask-jobqueue, Kubernetes): only the chunks' small results travel
back to the client, which writes them to the store, so the workers need no
shared file system.

The chunks are submitted as a window that moves as they complete (four per
worker thread, at least :data:`IN_FLIGHT`), so that a sweep of millions of
chunks holds a few of them at a time on the client and the scheduler.

A task that fails with an exception is retried ``retries`` times; a task whose
worker dies (killed, out of memory) is given to another worker by the
scheduler, as Dask does for every task. On Ctrl-C the tasks not finished are
cancelled and the chunks already written stay in the store.
"""

from __future__ import annotations

import itertools
import os
import signal
import threading
import uuid
from collections.abc import Callable, Mapping, Sequence
from contextlib import contextmanager, nullcontext
from typing import TYPE_CHECKING

from tumble._validate import ValidationError
from tumble.sweeps.plan import Plan
from tumble.sweeps.store import SweepStore

if TYPE_CHECKING:
    from distributed import Client, LocalCluster

__all__ = ["gpu_workers", "local_cluster", "run_chunks", "visible_gpus"]

_TRIM = "MALLOC_TRIM_THRESHOLD_"  # glibc's malloc setting that Dask gives its workers
#: The fewest chunks submitted at once (else four per worker thread): more are submitted as these complete,
#: so that the client and the scheduler hold a window of the sweep's tasks, not millions of them.
IN_FLIGHT = 32


def local_cluster(workers: int | None = None, *, gpus: Sequence[str] = ()) -> LocalCluster:
    """A :class:`distributed.LocalCluster` of ``workers`` single-threaded processes (default: one per core),
    every server on 127.0.0.1 (the scheduler's HTTP endpoint on a free port there).

    With ``gpus`` (ids as ``CUDA_VISIBLE_DEVICES`` names them: :func:`gpu_workers`), one process per GPU
    instead, named ``cuda-ID``, each with ``CUDA_VISIBLE_DEVICES=ID`` in its environment (set by its nanny
    before the worker starts, so CUDA, which reads it when a process first calls the driver, shows the
    worker that GPU alone, as its device 0) and ``1/len(gpus)`` of the host's memory.

    The workers run with glibc's own ``malloc`` thresholds. Dask starts its workers with
    ``MALLOC_TRIM_THRESHOLD_=65536`` (``distributed.nanny.pre-spawn-environ``, also left set in the process
    that started them), which fixes the ``mmap`` threshold too: every array of a chunk over 128 KiB is then
    mapped and its pages faulted afresh, and a sweep of chunks of 1e4 rigid bodies ran 12–15 % slower
    (docs/sweeps.md). With glibc's defaults a chunk reuses the memory the previous one freed, and a worker
    holds about one chunk's memory between tasks (379–405 MiB against Dask's 218 MiB, after five sweeps of
    chunks of 1e4 bodies). For Dask's setting, start a cluster and pass its client.

    The workers log critical errors only (``silence_logs=logging.CRITICAL``): a chunk's failure reaches the
    client with its traceback, and the rest is Dask's own bookkeeping, such as a cancelled chunk's
    ``CancelledError`` or a heartbeat that finds the scheduler closed when a sweep is interrupted (an
    interrupted ``tumble sweep`` says one line)."""
    import logging

    from distributed import LocalCluster

    n = (os.cpu_count() or 1) if workers is None else int(workers)
    with _glibc_malloc_defaults(), _interrupts_ignored():
        cluster = LocalCluster(n_workers=0 if gpus else n, threads_per_worker=1, processes=True, host="127.0.0.1",
                               dashboard_address="127.0.0.1:0", env={"NUMBA_NUM_THREADS": "1"},
                               silence_logs=logging.CRITICAL)
        if gpus:
            _start_one_worker_per_gpu(cluster, gpus)
    return cluster


def _start_one_worker_per_gpu(cluster: LocalCluster, gpus: Sequence[str]) -> None:
    """Start on ``cluster`` (none of its own yet) one worker per GPU of ``gpus``, from its worker template with
    the GPU's ``CUDA_VISIBLE_DEVICES``: distributed's ``SpecCluster`` starts what its ``worker_spec`` adds
    (entries need not be alike) when it corrects its state. A worker that fails to start closes the cluster."""
    template = cluster.new_spec
    for gpu in gpus:
        options = dict(template["options"], env={**template["options"]["env"], "CUDA_VISIBLE_DEVICES": gpu},
                       memory_limit=1 / len(gpus))  # a fraction of the host's memory
        cluster.worker_spec[f"cuda-{gpu}"] = {"cls": template["cls"], "options": options}
    try:
        cluster.sync(cluster._correct_state)
    except BaseException:
        cluster.close()
        raise


def visible_gpus(environ: Mapping[str, str] = os.environ, count: int | None = None) -> list[str]:
    """The GPUs this process may use, each named as ``CUDA_VISIBLE_DEVICES`` names it to a child process.

    CUDA numbers the GPUs a process sees 0, 1, …: those ``CUDA_VISIBLE_DEVICES`` lists (indices or UUIDs),
    in its order, up to its first entry that names none, or every GPU where it is unset. ``count`` is how
    many this process sees (default: the length of numba.cuda's device list, 0 where numba.cuda finds no
    GPU; its simulator's list has one). So visible GPU ``i`` is the ``i``-th entry of
    ``CUDA_VISIBLE_DEVICES``, or ``"i"`` where it is unset, and a child given it sees that GPU alone."""
    if count is None:
        from numba import cuda

        count = len(cuda.gpus) if cuda.is_available() else 0
    listed = environ.get("CUDA_VISIBLE_DEVICES")
    if listed is None:
        return [str(i) for i in range(count)]
    return [entry.strip() for entry in listed.split(",")][:count]


def gpu_workers(workers: int | None, gpus: Sequence[str] | None = None) -> list[str]:
    """The GPUs of ``gpus`` (default :func:`visible_gpus`) on which a sweep with ``device="cuda"`` and no
    client runs its chunks, one worker process each (:func:`local_cluster`); none: in this process.

    ``workers=None``: every GPU where there are more than one, none with one (or none: the run then says
    that it needs a GPU). ``workers=0``: none. ``workers=N``: the first ``N``; more than there are is
    refused, naming ``workers`` and the GPUs found."""
    gpus = visible_gpus() if gpus is None else list(gpus)
    if workers is None:
        return gpus if len(gpus) > 1 else []
    if int(workers) > len(gpus):
        raise ValidationError(f"workers: device='cuda' runs one worker per GPU, and numba.cuda finds "
                              f"{len(gpus)} GPU{'' if len(gpus) == 1 else 's'} here; got workers={workers}")
    return gpus[:int(workers)]


@contextmanager
def _interrupts_ignored():
    """Worker processes spawned inside ignore SIGINT: Ctrl-C in a terminal reaches every process of its group,
    and is the client's to handle (it cancels the chunks in flight and closes the cluster); a worker that took
    it printed Dask's tracebacks, 60-90 lines. An ignored signal stays ignored across ``exec`` and Python
    leaves it so. This process's handler comes back after (from the main thread only: elsewhere nothing is
    changed)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, previous)


@contextmanager
def _logs_silenced():
    """This process's ``distributed``, ``tornado`` and ``asyncio`` loggers silent inside (levels restored after).

    For closing the sweep's own cluster on Ctrl-C: the interrupt cancels the client's call in flight from its
    event loop, whose callbacks then log the cancellation's traceback, and the scheduler's closing logs its
    workers' lost heartbeats, all while the chunks written are safe; the command says so in one line."""
    import logging

    loggers = [logging.getLogger(name) for name in ("distributed", "tornado", "asyncio")]
    levels = [logger.level for logger in loggers]
    for logger in loggers:
        logger.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for logger, level in zip(loggers, levels, strict=True):
            logger.setLevel(level)


@contextmanager
def _glibc_malloc_defaults():
    """Worker processes spawned inside get no ``MALLOC_TRIM_THRESHOLD_`` (from Dask's configuration or from this
    process's environment, where an earlier Dask cluster may have left it); this process's value comes back
    after."""
    import dask

    saved = os.environ.pop(_TRIM, None)
    try:
        with dask.config.set({f"distributed.nanny.pre-spawn-environ.{_TRIM}": None}):
            yield
    finally:
        if saved is not None:
            os.environ[_TRIM] = saved


def _run_chunk(plan: Plan, k: int):
    _numba_settings_from_environment()
    return plan.run(k)


def _numba_settings_from_environment() -> None:
    """Hold a chunk to the worker's ``NUMBA_NUM_THREADS`` (1 on :func:`local_cluster`), where it is set.

    Numba reads its settings when imported, and a worker process started by ``spawn`` imports it before the
    Nanny sets the worker's environment (it re-imports the client's ``__main__``, and with it tumble): its
    pool then starts with one thread per core (2 workers ran 4 threads on 2 cores), and the first
    compilation after the pool started (a kernel not in the cache) failed, Numba refusing to change the
    number of running threads. So the settings are read again before the first chunk starts the pool (a
    no-op once they agree), and the chunk's thread is held to the number (Numba's count is per thread; the
    pool itself keeps the size it was imported with)."""
    limit = os.environ.get("NUMBA_NUM_THREADS")
    if limit is None:
        return
    import numba
    from numba.core import config
    from numba.np.ufunc import parallel

    config.reload_config()
    numba.set_num_threads(max(1, min(int(limit), parallel.NUM_THREADS)))


def run_chunks(plan: Plan, store: SweepStore, *, client: Client | None = None, workers: int | None = None,
               gpus: Sequence[str] = (), progress: Callable[[int, int], None] | None = None,
               retries: int = 2) -> int:
    """Compute the chunks missing from ``store`` on Dask and write each as it completes; return how many
    were computed. ``gpus``: the sweep's own cluster has one worker per GPU (:func:`local_cluster`).
    ``progress(done, total)`` counts chunks (those already in the store included)."""
    from distributed import Client, as_completed

    missing = store.missing()
    total = len(plan.chunks)
    if progress is not None:
        progress(total - len(missing), total)
    if not missing:
        return 0
    if workers == 0 and client is None:  # in this process, chunk after chunk
        for n, k in enumerate(missing, start=total - len(missing) + 1):
            store.write(k, plan.run(k))
            if progress is not None:
                progress(n, total)
        return len(missing)
    cluster = None
    if client is None:
        cluster = local_cluster(workers, gpus=gpus)
        client = Client(cluster)
    elif workers is not None:
        raise ValidationError("workers: give it only without client= (a client's cluster has its own workers)")
    # keys of this call alone: two sweeps on one scheduler never share a task, whatever their settings
    run = f"tumble-sweep-{plan.token()}-{uuid.uuid4().hex}"
    if cluster is None:  # workers perhaps elsewhere, with another cache: give them this process's compiled code
        from tumble.sweeps.shipping import compiled_for

        client.register_plugin(compiled_for(plan), name=run)
    futures: dict = {}  # the chunks in flight: future → chunk

    def submit(k: int):
        future = client.submit(_run_chunk, plan, k, key=f"{run}-{k}", retries=retries, pure=False)
        futures[future] = k
        return future

    todo = iter(missing)
    window = max(IN_FLIGHT, 4 * sum(client.nthreads().values()))
    interrupted = False
    try:
        queue = as_completed([submit(k) for k in itertools.islice(todo, window)], loop=client.loop)
        done = total - len(missing)
        for future in queue:  # on this client, default or not
            store.write(futures.pop(future), future.result())
            future.release()
            following = next(todo, None)
            if following is not None:
                queue.add(submit(following))
            done += 1
            if progress is not None:
                progress(done, total)
        return len(missing)
    except KeyboardInterrupt:
        interrupted = True
        raise
    finally:
        for future in futures:
            if not future.done():
                future.cancel()
        if cluster is not None:
            with _logs_silenced() if interrupted else nullcontext():
                client.close()
                cluster.close()
        elif client.status == "running":  # a scheduler gone leaves no plugin behind
            client.unregister_worker_plugin(run)
