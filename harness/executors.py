"""Where campaign tasks run: in this process, a local process pool, or a Dask cluster.

All three call the same pure function on the same task objects; since every task carries its
own seed, the numbers do not depend on which one runs them.
"""
from __future__ import annotations

import concurrent.futures as cf
import multiprocessing
from collections.abc import Callable, Iterable, Iterator
from typing import Any


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

    def __exit__(self, *exc) -> None:
        self.close()


class LocalPool(Executor):
    """A process pool on this machine (the default)."""

    def __init__(self, workers: int) -> None:
        self.workers = workers
        self.description = f"local process pool, {workers} workers"
        self.pool = cf.ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("fork"))

    def imap_unordered(self, fn, items, *args):
        futures = {self.pool.submit(fn, item, *args): item for item in items}
        for fut in cf.as_completed(futures):
            yield futures[fut], fut.result()

    def close(self) -> None:
        self.pool.shutdown(wait=True, cancel_futures=True)


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
    if scheduler:
        return DaskExecutor(scheduler, workers)
    if workers <= 1:
        return Executor()
    return LocalPool(workers)
