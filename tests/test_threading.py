"""Parallel Numba kernels launched from two threads at once must not abort the process (the app's UI thread and the
background job runner both run them)."""
from __future__ import annotations

import threading

import numpy as np

import volviz  # noqa: F401  (sets the thread-safe threading layer)
from volviz.optics import TransferFunction
from volviz.optics.table3d import build_table3d


def test_parallel_kernels_from_two_threads() -> None:
    import numba

    tf = TransferFunction([0.0, 0.5, 1.0], [[1, 0, 0], [0, 1, 0], [0, 0, 1]], [0.0, 8.0, 2.0])
    results: list[np.ndarray] = []
    errors: list[BaseException] = []

    def work() -> None:
        try:
            results.append(build_table3d(tf, n_s=48, n_l=16).rgba)
        except BaseException as exc:  # pragma: no cover - reported below
            errors.append(exc)

    threads = [threading.Thread(target=work) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors and len(results) == 3
    assert all(np.array_equal(results[0], r) for r in results[1:])
    assert numba.threading_layer() in ("omp", "tbb")
