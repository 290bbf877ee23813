"""Where campaign tasks run: in this process, a local process pool, or a Dask cluster.

All three call the same pure function on the same task objects; since every task carries its
own seed, the numbers do not depend on which one runs them.
"""
from __future__ import annotations

import concurrent.futures as cf
import multiprocessing
import os
import signal
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from typing import Any

from harness.errors import OptionError


class Executor:
    """``imap_unordered(fn, items)`` yields ``(item, result)`` as results arrive."""

    description = "serial"

    def imap_unordered(self, fn: Callable, items: Iterable, *args: Any) -> Iterator[tuple[Any, Any]]:
        for item in items:
            yield item, fn(item, *args)

    def close(self) -> None:
        pass

    def __enter__(self) -> "Executor":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is not None:
            self.abort()
        else:
            self.close()

    def abort(self) -> None:
        """Stop at once (an interruption or an error): unfinished work is dropped."""
        self.close()


ORPHAN_POLL_S = 0.5
"""How often a pool worker checks that the process that started it is still alive."""


def _exit_when_orphaned(parent_pid: int) -> None:
    while os.getppid() == parent_pid:
        time.sleep(ORPHAN_POLL_S)
    os._exit(1)  # the parent is gone (kill -9): nobody will read our results


def _worker_init(parent_pid: int) -> None:
    """In each pool worker: leave Ctrl-C to the parent (no traceback per worker), and exit when
    the parent dies instead of living on as an orphan."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    threading.Thread(target=_exit_when_orphaned, args=(parent_pid,), daemon=True,
                     name="sidbench-orphan-watch").start()


class LocalPool(Executor):
    """A process pool on this machine (the default)."""

    def __init__(self, workers: int) -> None:
        self.workers = workers
        self.description = f"local process pool, {workers} workers"
        self.pool = cf.ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("fork"),
                                           initializer=_worker_init, initargs=(os.getpid(),))

    def imap_unordered(self, fn, items, *args):
        futures = {self.pool.submit(fn, item, *args): item for item in items}
        for fut in cf.as_completed(futures):
            yield futures[fut], fut.result()

    def close(self) -> None:
        self.pool.shutdown(wait=True, cancel_futures=True)

    def abort(self) -> None:
        processes = list((getattr(self.pool, "_processes", None) or {}).values())
        self.pool.shutdown(wait=False, cancel_futures=True)
        for proc in processes:
            proc.terminate()
        for proc in processes:
            proc.join(timeout=5)


class DaskExecutor(Executor):
    """A Dask cluster: ``'local'`` starts a LocalCluster on loopback, otherwise the address of
    a running scheduler (``tcp://HOST:PORT``)."""

    def __init__(self, scheduler: str, workers: int) -> None:
        from distributed import Client, LocalCluster
        self.cluster = None
        if scheduler == "local":
            self.cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                        host="127.0.0.1", dashboard_address=":0")
            self.client = Client(self.cluster)
            self.description = f"dask LocalCluster, {workers} workers"
        else:
            self.client = Client(scheduler, timeout="30s")
            n = len(self.client.scheduler_info().get("workers", {}))
            self.description = f"dask scheduler {scheduler}, {n} workers"

    def imap_unordered(self, fn, items, *args):
        from distributed import as_completed
        items = list(items)
        futures = {self.client.submit(fn, item, *args, pure=False): i for i, item in enumerate(items)}
        for fut in as_completed(list(futures)):
            yield items[futures[fut]], fut.result()

    def close(self) -> None:
        self.client.close()
        if self.cluster is not None:
            self.cluster.close()


def make_executor(scheduler: str | None, workers: int) -> Executor:
    """Serial for one worker without a scheduler, a process pool otherwise, Dask when asked."""
    if workers < 1:
        raise OptionError(f"--workers must be at least 1, not {workers}")
    if scheduler:
        return DaskExecutor(scheduler, workers)
    if workers <= 1:
        return Executor()
    return LocalPool(workers)
