"""Numba's thread count per calling thread, for work split over several Python threads at once.

Numba's thread count is a per-thread setting. Two Python threads that each launch parallel kernels with every core
oversubscribe the machine (OpenMP gives each launching thread its own team, whose idle members spin), so work split
over ``parts`` threads gives each its share of the calling thread's count (at least one)."""
from __future__ import annotations

from contextlib import contextmanager
from typing import Iterator

import numba


def share(parts: int) -> int:
    """The calling thread's Numba thread count divided among ``parts`` threads (at least 1 each)."""
    return max(1, int(numba.get_num_threads()) // max(1, parts))


@contextmanager
def numba_threads(count: int) -> Iterator[None]:
    """Run the block's parallel kernels on ``count`` threads (this thread only); the previous count afterwards."""
    saved = int(numba.get_num_threads())
    numba.set_num_threads(max(1, min(int(count), int(numba.config.NUMBA_NUM_THREADS))))  # type: ignore[attr-defined]
    try:
        yield
    finally:
        numba.set_num_threads(saved)
