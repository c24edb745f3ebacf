"""``volviz.numba_threads``: a thread's Numba thread count set for a block and restored, and the share of work split
over several threads."""
from __future__ import annotations

import threading

import numba

from volviz.numba_threads import numba_threads, share


def test_block_runs_with_the_count_and_restores_it() -> None:
    before = numba.get_num_threads()
    with numba_threads(1):
        assert numba.get_num_threads() == 1
    assert numba.get_num_threads() == before
    with numba_threads(10_000):                     # capped at the pool's size
        assert numba.get_num_threads() == numba.config.NUMBA_NUM_THREADS
    assert numba.get_num_threads() == before


def test_the_setting_is_the_calling_threads_own() -> None:
    seen: list[int] = []
    with numba_threads(1):
        worker = threading.Thread(target=lambda: seen.append(numba.get_num_threads()))
        worker.start()
        worker.join()
    assert seen == [numba.config.NUMBA_NUM_THREADS]


def test_share_divides_the_callers_count() -> None:
    total = numba.config.NUMBA_NUM_THREADS
    with numba_threads(total):
        assert share(2) == max(1, total // 2)
        assert share(1) == total
        assert share(4 * total) == 1
