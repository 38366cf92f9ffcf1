"""Where batch jobs run: a local process pool or a Dask cluster, behind one interface.

Both are `concurrent.futures` executors (Dask through ``Client.get_executor()``), so the
runner (`execute.batch.runner`) has one code path and ships the same module-level job
functions to either.

- ``local``: `concurrent.futures.ProcessPoolExecutor` with ``workers`` processes, started
  by a fork server (the parent has a progress-bar thread; forking it is unsafe), a fresh
  process for every job (`local_engine`). One worker dying breaks the whole pool
  (`BrokenProcessPool`); the runner then calls `Engine.restart`.
- ``dask``: ``distributed.Client(address)`` against a running scheduler, or a
  ``LocalCluster`` of ``workers`` single-threaded worker processes when no address is
  given (``processes=False`` runs the workers as threads, for tests). Dask retries a
  task whose worker died and reports ``KilledWorker`` after repeated deaths, which the
  runner records like any job error.
"""

from __future__ import annotations

import logging
import multiprocessing
from concurrent.futures import Executor, Future, ProcessPoolExecutor
from typing import Any

__all__ = ["Engine", "dask_engine", "local_engine", "open_engine"]

log = logging.getLogger(__name__)


class Engine:
    """A `concurrent.futures` executor plus what the runner needs to know about it.

    Attributes:
        name: ``local`` or ``dask``.
        slots: jobs the runner keeps in flight (one per worker core).
        description: one line for the user (workers, address, dashboard).
        breaks_on_crash: a dead worker breaks the executor (process pools); the runner
            then isolates the jobs that were in flight and calls `restart`.
    """

    def __init__(self, name: str, executor: Executor, slots: int, description: str,
                 breaks_on_crash: bool, restart=None, close=None):
        self.name = name
        self.executor = executor
        self.slots = max(1, int(slots))
        self.description = description
        self.breaks_on_crash = breaks_on_crash
        self._restart = restart
        self._close = close

    def submit(self, fn, *args: Any) -> Future:
        """Run ``fn(*args)`` on a worker."""
        return self.executor.submit(fn, *args)

    def restart(self) -> None:
        """Replace a broken executor by a fresh one."""
        if self._restart is None:
            raise RuntimeError(f"engine {self.name} cannot restart")
        self.executor = self._restart(self.executor)

    def close(self, cancel: bool = False) -> None:
        """Shut down (cancel jobs not started when ``cancel``)."""
        try:
            if isinstance(self.executor, ProcessPoolExecutor):
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


def local_engine(workers: int) -> Engine:
    """A local process pool of ``workers`` processes, a fresh one for every job.

    A fresh process per job keeps a batch cell identical to ``plan-ladder`` with its
    seed: OMPL's random numbers can be seeded only once per process
    (`planner.paths.limb_rrt`), so a worker that had planned before would draw on from where
    its previous jobs left them. The fork server imports the heavy modules once.
    """
    ctx = multiprocessing.get_context("forkserver")
    ctx.set_forkserver_preload(list(FORKSERVER_PRELOAD))  # no effect once it has started

    def make() -> ProcessPoolExecutor:
        return ProcessPoolExecutor(max_workers=workers, mp_context=ctx, max_tasks_per_child=1)

    def restart(old: Executor) -> Executor:
        old.shutdown(wait=False, cancel_futures=True)
        return make()

    return Engine("local", make(), workers, f"local process pool, {workers} worker"
                  f"{'s' * (workers != 1)}", True, restart)


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
    return Engine("dask", client.get_executor(pure=False), slots, where, False, None, close)


def open_engine(name: str, workers: int, address: str | None = None) -> Engine:
    """The engine ``name`` (``local`` or ``dask``); use it as a context manager."""
    if name == "local":
        return local_engine(workers)
    if name == "dask":
        return dask_engine(address, workers)
    raise ValueError(f"unknown engine {name!r}: local or dask")
