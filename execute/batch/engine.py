"""Where batch jobs run: a local process pool or a Dask cluster, behind one interface.

Both are `concurrent.futures` executors (Dask through ``Client.get_executor()``), so the
runner (`execute.batch.runner`) has one code path and ships the same module-level job
functions to either.

- ``local``: a fresh worker process for every job, started by a fork server (the parent
  has a progress-bar thread; forking it is unsafe), at most ``workers`` at a time
  (`local_engine`, `FreshProcessExecutor`). A worker dying fails its job with
  `BrokenProcessPool`, which the runner records as that job's error.
- ``dask``: ``distributed.Client(address)`` against a running scheduler, or a
  ``LocalCluster`` of ``workers`` single-threaded worker processes when no address is
  given (``processes=False`` runs the workers as threads, for tests). Dask retries a
  task whose worker died and reports ``KilledWorker`` after repeated deaths, which the
  runner records like any job error.
"""

from __future__ import annotations

import logging
import multiprocessing
import threading
from concurrent.futures import Executor, Future, ProcessPoolExecutor
from typing import Any

__all__ = ["Engine", "FreshProcessExecutor", "dask_engine", "local_engine", "open_engine"]

log = logging.getLogger(__name__)


class Engine:
    """A `concurrent.futures` executor plus what the runner needs to know about it.

    Attributes:
        name: ``local`` or ``dask``.
        slots: jobs the runner keeps in flight (one per worker core).
        description: one line for the user (workers, address, dashboard).
    """

    def __init__(self, name: str, executor: Executor, slots: int, description: str,
                 close=None):
        self.name = name
        self.executor = executor
        self.slots = max(1, int(slots))
        self.description = description
        self._close = close

    def submit(self, fn, *args: Any) -> Future:
        """Run ``fn(*args)`` on a worker."""
        return self.executor.submit(fn, *args)

    def close(self, cancel: bool = False) -> None:
        """Shut down (cancel jobs not started when ``cancel``)."""
        try:
            if isinstance(self.executor, FreshProcessExecutor):
                self.executor.shutdown(wait=not cancel, cancel_futures=cancel)
            else:  # Dask's ClientExecutor cancels its pending futures itself
                self.executor.shutdown(wait=not cancel)
        finally:
            if self._close is not None:
                self._close()

    def __enter__(self) -> Engine:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self.close(cancel=exc_type is not None)

    def __repr__(self) -> str:
        return f"Engine({self.description})"


#: Imported once by the fork server, so that a fresh process per job starts warm.
FORKSERVER_PRELOAD = ("planner.search", "planner.output", "execute.validate.simulate")


class FreshProcessExecutor(Executor):
    """Runs each submitted call in a new process of its own: a one-worker
    `ProcessPoolExecutor` per call, shut down when the call ends.

    This is what ``ProcessPoolExecutor(max_tasks_per_child=1)`` promises, without its
    replacement of exited workers, which on Python 3.11–3.13 can leave queued calls with
    no worker, for ever (CPython gh-115634; a `batch-eval` test hung on it). The caller
    bounds how many calls run at once (`execute.batch.runner` keeps ``slots`` in flight).

    Args:
        mp_context: the multiprocessing context the workers start from.
    """

    def __init__(self, mp_context):
        self._ctx = mp_context
        self._pools: set[ProcessPoolExecutor] = set()
        self._lock = threading.Lock()
        self._shut = False

    def submit(self, fn, /, *args, **kwargs) -> Future:
        with self._lock:
            if self._shut:
                raise RuntimeError("cannot submit after shutdown")
            pool = ProcessPoolExecutor(max_workers=1, mp_context=self._ctx)
            self._pools.add(pool)
        fut = pool.submit(fn, *args, **kwargs)
        fut.add_done_callback(lambda _f: self._retire(pool))
        return fut

    def _retire(self, pool: ProcessPoolExecutor) -> None:
        with self._lock:
            self._pools.discard(pool)
        pool.shutdown(wait=False)

    def shutdown(self, wait: bool = True, *, cancel_futures: bool = False) -> None:
        with self._lock:
            self._shut = True
            pools = list(self._pools)
        for pool in pools:
            pool.shutdown(wait=wait, cancel_futures=cancel_futures)


def local_engine(workers: int) -> Engine:
    """Local processes, at most ``workers`` at a time, a fresh one for every job.

    A fresh process per job keeps a batch cell identical to ``plan-ladder`` with its
    seed: OMPL's random numbers can be seeded only once per process
    (`planner.paths.limb_rrt`), so a worker that had planned before would draw on from where
    its previous jobs left them. The fork server imports the heavy modules once.
    """
    ctx = multiprocessing.get_context("forkserver")
    ctx.set_forkserver_preload(list(FORKSERVER_PRELOAD))  # no effect once it has started

    return Engine("local", FreshProcessExecutor(ctx), workers, f"local processes, "
                  f"{workers} at a time, a fresh one per job")


def dask_engine(address: str | None = None, workers: int = 1, processes: bool = True
                ) -> Engine:
    """A Dask executor: a client of ``address``, or of a new ``LocalCluster``.

    Args:
        address: scheduler address (``tcp://host:8786``); None starts a LocalCluster.
        workers: LocalCluster workers (one thread each); with an address, the number of
            jobs kept in flight is the cluster's thread count instead.
        processes: LocalCluster workers are processes (True) or threads in this process.

    Raises:
        ImportError: ``distributed`` is not installed (the project's ``dask`` extra).
        OSError: the scheduler cannot be reached.
    """
    from distributed import Client, LocalCluster

    # distributed sets its own loggers to INFO; keep its chatter out of the user's
    # terminal unless batch-eval runs verbose (the root logger then passes INFO).
    if not logging.getLogger().isEnabledFor(logging.INFO):
        logging.getLogger("distributed").setLevel(logging.WARNING)
    cluster = None
    if address is None:
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=processes,
                               dashboard_address=None, silence_logs=logging.ERROR)
        client = Client(cluster)
        slots = workers
        where = f"Dask LocalCluster, {workers} worker{'s' * (workers != 1)}" + \
                ("" if processes else " (threads)")
    else:
        client = Client(address, timeout=10)
        slots = sum(client.nthreads().values()) or workers
        where = f"Dask cluster {address}, {slots} thread{'s' * (slots != 1)}"

    def close() -> None:
        client.close()
        if cluster is not None:
            cluster.close()

    # pure=False: every submission is its own task (no key deduplication or caching).
    return Engine("dask", client.get_executor(pure=False), slots, where, close)


def open_engine(name: str, workers: int, address: str | None = None) -> Engine:
    """The engine ``name`` (``local`` or ``dask``); use it as a context manager."""
    if name == "local":
        return local_engine(workers)
    if name == "dask":
        return dask_engine(address, workers)
    raise ValueError(f"unknown engine {name!r}: local or dask")
