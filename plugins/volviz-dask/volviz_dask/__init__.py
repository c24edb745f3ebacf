"""volviz compression backend on dask.distributed (entry point ``dask`` in ``volviz.compression_backends``).

``volviz compress --series --scheduler tcp://host:8786`` and ``compress_series(..., scheduler=address)`` send each
independent part of the series (I volume to I volume) to the cluster as one task; the client reads the volumes and
sends each task its own, so workers need no access to the input files. Results come back as they finish; volviz
writes them in storage order, so the store is bit-identical to a local run.
"""
from __future__ import annotations

from typing import Any, Callable, Iterable, Iterator


def run(address: str, func: Callable[..., Any], tasks: Iterable[tuple]) -> Iterator[Any]:
    """``func(*task)`` for every task on the dask.distributed scheduler at ``address``; results as they complete."""
    from distributed import Client, as_completed

    with Client(address) as client:
        futures = [client.submit(func, *task, pure=False) for task in tasks]
        for future in as_completed(futures):
            yield future.result()
