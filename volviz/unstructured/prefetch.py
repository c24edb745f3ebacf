"""Visibility sorting for the next camera in the background while the current frame draws.

The sort (MPVO with boundary relations, ``volviz.unstructured.sort``) depends only on the eye, the view frame and
the image size, not on the transfer function, so when the next camera is known (a camera path, a movie, a fly-through
extrapolated by the caller) its order can be computed on the job runner's worker while the current frame rasterises.
The sort kernels are Numba ``nogil``, so the two really run at the same time. ``render_path`` does this for a list of
cameras; ``SortPrefetcher`` is the building block (used by ``volviz.render.pt_prop.PTVolume``).

A prefetched order is used only for a camera that matches the one it was sorted for (position, view frame, view
angle, projection and image size equal to 1e-9 relative; the clipping range does not enter the sort); otherwise
the frame sorts as usual, so a wrong guess costs time, never correctness.
"""
from __future__ import annotations

import threading
import time
from typing import Any, Iterator, Optional, Sequence

import numpy as np

from volviz.jobs import JobRunner
from volviz.model.camera import Camera
from volviz.model.datasets import TetMesh
from volviz.unstructured.render import render
from volviz.unstructured.sort import SortResult, visibility_order
from volviz.unstructured.topology import topology

__all__ = ["SortPrefetcher", "render_path", "same_view"]


def _view_key(camera: Camera, size: tuple[int, int]) -> np.ndarray:
    r, u, f = camera.frame()
    return np.concatenate([np.asarray(camera.position, dtype=np.float64), r, u, f,
                           [float(camera.view_angle), float(camera.parallel), float(camera.parallel_scale),
                            float(size[0]), float(size[1])]])


def same_view(a: Camera, b: Camera, size_a: tuple[int, int], size_b: tuple[int, int]) -> bool:
    """Whether two cameras give the same visibility order (clipping ranges aside), to 1e-9 relative."""
    ka, kb = _view_key(a, size_a), _view_key(b, size_b)
    scale = max(1.0, float(np.abs(ka[:3]).max()), float(np.abs(kb[:3]).max()))
    return bool(np.allclose(ka, kb, rtol=1e-9, atol=1e-9 * scale))


class SortPrefetcher:
    """Sorts ``mesh`` for a future camera on a background worker; ``take`` hands the order to the frame that needs it.

    ``runner``: a shared ``volviz.jobs.JobRunner`` (the app's), or None for a private one-worker runner (closed by
    ``close``). A newer ``prefetch`` supersedes an unfinished older one."""

    def __init__(self, mesh: TetMesh, *, sort: str = "mpvo", nonconvex: str = "auto",
                 runner: Optional[JobRunner] = None) -> None:
        self.mesh = mesh
        self.topo = topology(mesh)          # built here, on the caller's thread, once
        self.sort, self.nonconvex = sort, nonconvex
        self._own_runner = runner is None
        self.runner = runner or JobRunner(max_workers=1)
        self._job: Any = None
        self._for: Optional[tuple[Camera, tuple[int, int]]] = None
        self._lock = threading.Lock()       # ``take`` may run on a worker while the GUI thread prefetches
        self.hits = 0
        self.misses = 0

    def _sort(self, camera: Camera, size: tuple[int, int], progress: Any = None) -> SortResult:
        return visibility_order(self.topo, camera, size, self.sort, self.nonconvex)

    def prefetch(self, camera: Camera, size: tuple[int, int]) -> None:
        """Start sorting for ``camera`` at image ``size`` in the background (no-op if that sort is already there)."""
        size = (int(size[0]), int(size[1]))
        with self._lock:
            if self._for is not None and same_view(self._for[0], camera, self._for[1], size):
                return
            self._for = (camera, size)
            self._job = self.runner.submit(self._sort, camera, size, name="sort for the next camera",
                                           key=f"sort-prefetch-{id(self)}")

    def pending(self) -> Optional[tuple[Camera, tuple[int, int]]]:
        """The camera and size of the sort in flight or finished and not yet taken, or None."""
        with self._lock:
            return self._for if self._job is not None else None

    def take(self, camera: Camera, size: tuple[int, int], consume: bool = True) -> Optional[SortResult]:
        """The prefetched order if it was made for this view (waits for it to finish), else None. ``consume=False``
        leaves it for another taker (e.g. the frame drawn meanwhile on the GUI thread)."""
        size = (int(size[0]), int(size[1]))
        with self._lock:
            job, made_for = self._job, self._for
            if job is None or made_for is None or not same_view(made_for[0], camera, made_for[1], size):
                self.misses += 1
                return None
            if consume:
                self._job, self._for = None, None
        outcome = job.outcome()            # outside the lock: a prefetch meanwhile only replaces the job
        if not outcome.ok:
            self.misses += 1
            return None
        self.hits += 1
        return outcome.result

    def close(self) -> None:
        if self._job is not None:
            self._job.cancel()
        if self._own_runner:
            self.runner.shutdown(wait=True)

    def __enter__(self) -> "SortPrefetcher":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def render_path(mesh: TetMesh, tf: Any, cameras: Sequence[Camera], size: tuple[int, int] = (512, 512), *,
                sort: str = "mpvo", nonconvex: str = "auto", runner: Optional[JobRunner] = None,
                **render_opts: Any) -> Iterator[tuple[np.ndarray, Any]]:
    """Render ``cameras`` in order with ``volviz.unstructured.render(method="pt")``, sorting camera i + 1 in the
    background while frame i rasterises. Yields ``(image, UnstructuredRenderStats)``; ``stats.sort_s`` is then only the
    wait for the prefetched order plus the zero-opacity filter, and ``stats.extra["sort_prefetched"]`` says whether the
    order came from the background. Images equal those of separate ``render`` calls exactly."""
    size = (int(size[0]), int(size[1]))
    with SortPrefetcher(mesh, sort=sort, nonconvex=nonconvex, runner=runner) as pre:
        if cameras:
            pre.prefetch(cameras[0], size)
        for i, cam in enumerate(cameras):
            t_wait = time.perf_counter()
            res = pre.take(cam, size)
            t_wait = time.perf_counter() - t_wait
            if i + 1 < len(cameras):
                pre.prefetch(cameras[i + 1], size)
            order = None if res is None else res.order
            img, st = render(mesh, tf, cam, size, "pt", sort=sort, nonconvex=nonconvex, order=order,
                             return_stats=True, **render_opts)
            st.sort_s += t_wait
            st.total_s += t_wait
            st.extra["sort_prefetched"] = res is not None
            if res is not None:
                st.cycles, st.boundary_relations = res.cycles, res.boundary_relations
                st.extra["background_sort_s"] = res.seconds
            yield img, st
