"""The back-to-front order the GPU PT pass draws its cells in (Roettger §9.1; ``volviz.render.gl_pt``): made for
each frame's camera before the render (``visibility_order``, as the CPU ``pt``, zero-opacity and NaN cells culled),
taken from a sort prefetched for a known camera, made on a worker by the view calls ``begin`` / ``compute`` /
``finish`` while the GPU draws, or during an interaction the previous frame's camera's order while this one's is
sorted on the worker (issue #29: the order drawn is never older than the previous frame's camera). Each drawn frame
logs (camera serial, order serial): the order's age in frames."""
from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any, Optional, TypedDict

import numpy as np

from volviz.jobs import ProgressCallback
from volviz.model.camera import Camera
from volviz.render.image_overlay import window_size

if TYPE_CHECKING:   # type-only: the sort's classes, loaded only when a PT order is computed
    from volviz.unstructured.prefetch import SortPrefetcher
    from volviz.unstructured.sort import SortResult
    from volviz.unstructured.topology import Topology

__all__ = ["CellOrder", "OrderRequest", "order_key"]


class OrderRequest(TypedDict):
    """What ``CellOrder.begin`` asks a worker to sort (``compute``) and ``finish`` checks the order against."""

    camera: Camera
    size: tuple[int, int]
    key: tuple[object, ...]
    topo: Topology
    preview: bool
    serial: int
    have: bool            # the volume has this order already: nothing to sort
    prefetcher: Optional[SortPrefetcher]


def order_key(cam: Camera, size: tuple[int, ...]) -> tuple[object, ...]:
    """What a visibility order depends on: the camera and the image size."""
    return (tuple(cam.position), tuple(cam.focal_point), tuple(cam.view_up), cam.view_angle, cam.parallel,
            cam.parallel_scale, tuple(size))


class CellOrder:
    """The order state of a volume drawn in ``renderer`` (a base of ``GLPTVolume``): it sorts the cells of ``topo``
    (the volume's ``mesh``'s topology) with ``sort`` / ``nonconvex`` (as ``visibility_order``) and hands the
    order with the cells' visibility (``_vis``) to ``_set_index_buffer``, which the volume defines: it draws the
    visible ones in that order and returns them.

    ``order``: the cells drawn, back to front; ``reuse_order = True`` never sorts in a render: it draws the newest
    order it has. ``follows_camera``: during an interaction each frame starts its camera's sort (``_follow``);
    False: a subclass gives the order itself (``gl_nature.CloudPTVolume``: each frame's leaves)."""

    follows_camera = True
    FRAME_LOG = 1000
    renderer: Any
    mesh: Any
    topo: Any
    stats: dict[str, Any]
    _vis: np.ndarray

    def __init__(self, sort: str, nonconvex: str) -> None:
        self.sort, self.nonconvex = sort, nonconvex
        self.order: np.ndarray | None = None       # the drawn cells, back to front
        self.reuse_order = False                    # keep the last order whatever the camera (during interaction)
        self._sorted: np.ndarray | None = None      # the last full visibility order (all cells)
        self._sorted_key: Any = None                # the camera and size that order was made for
        self._recull = False                        # the TF changed: cull the last order again (no new sort)
        self._cycles = 0
        self._prefetcher: Any = None
        self._order_key: Any = None
        # the order's age in frames (issue #29): a serial per camera drawn (a new one when a frame's camera differs
        # from the previous frame's), the serial the drawn order was made for, and per drawn frame the two
        self.camera_serial = 0
        self.order_serial = 0
        self.frames: list[tuple[int, int]] = []     # (camera serial, order serial) of the last FRAME_LOG frames
        self._frame_key: Any = None
        self._frame_sort: tuple[int, Camera, tuple[int, int]] | None = None   # the frame sort on the worker

    def _set_index_buffer(self, order: np.ndarray, visible: np.ndarray) -> np.ndarray:
        raise NotImplementedError

    def _camera(self) -> Camera:
        return Camera.from_pyvista(self.renderer.GetActiveCamera())

    def _order_frame(self, cam: Camera, size: tuple[int, int]) -> None:
        """Before a render for ``cam`` at ``size``: the back-to-front index buffer for this camera (unchanged cameras
        keep theirs; a prefetched order for this camera is taken; with ``reuse_order`` the last order is kept for any
        camera, but never one older than the previous frame's camera: ``_follow``)."""
        # heavy: the sort's Numba kernels and SciPy, loaded only when a PT order is computed
        from volviz.unstructured.sort import visibility_order

        key = order_key(cam, size)
        if key != self._frame_key:
            self.camera_serial += 1
            self._frame_key = key
        newer = self._frame_sort is not None and self._frame_sort[0] > self.order_serial
        if key == self._order_key and self._sorted is not None and not self._recull and not newer:
            self._log_frame()
            return
        t0 = time.perf_counter()
        exact = self._sorted is not None and key == self._sorted_key
        res = None if exact or self._prefetcher is None else self._prefetcher.take(cam, size)
        serial, made_for = self.camera_serial, key
        if not exact and res is None and self.reuse_order and self._sorted is not None and self.follows_camera:
            res, serial, made_for = self._follow(cam, size)
        prefetched = res is not None
        if not exact and res is None and not (self.reuse_order and self._sorted is not None):
            res = visibility_order(self.topo, cam, size, self.sort, self.nonconvex)
        if res is not None:
            self._sorted, self._cycles, self._sorted_key = res.order, int(res.cycles), made_for
            self.order_serial = serial
        elif exact:
            self.order_serial = self.camera_serial
        self._recull = False
        t1 = time.perf_counter()
        assert self._sorted is not None  # this order, a prefetched one, a fresh sort or the earlier one reused
        cells = self._set_index_buffer(self._sorted, self._vis)
        self.order, self._order_key = cells, key
        self.stats = {"method": "pt-gl", "sort_s": t1 - t0, "order_s": time.perf_counter() - t1,
                      "n_visible": int(len(cells)), "cycles": self._cycles, "sorted": res is not None,
                      "sort_prefetched": prefetched, "order_reused": not exact and res is None}
        self._log_frame()

    def _log_frame(self) -> None:
        self.frames.append((self.camera_serial, self.order_serial))
        del self.frames[:-self.FRAME_LOG]

    def _sorter(self) -> Any:
        """The background sorter (``volviz.unstructured.prefetch.SortPrefetcher``), made at its first use."""
        # heavy: the sort's Numba kernels and SciPy (through the prefetcher), only when sorting ahead
        from volviz.unstructured.prefetch import SortPrefetcher

        if self._prefetcher is None:
            self._prefetcher = SortPrefetcher(self.mesh, sort=self.sort, nonconvex=self.nonconvex)
        return self._prefetcher

    def _follow(self, cam: Camera, size: tuple[int, int]) -> tuple[Any, int, Any]:
        """A frame during an interaction (``reuse_order``), for a camera with no order yet: take the order of the
        sort the previous frame started on the worker (waiting for it: a sort of the Blunt Fin takes ~13 ms, which
        it has had the previous frame's draw to do), and start this camera's. So the drawn order is never older than
        the previous frame's camera, and each camera's order is made on the worker within one frame (issue #29).
        Returns (the order or None, the camera serial and ``_order_key`` it was made for)."""
        res, serial, made_for = None, self.order_serial, self._sorted_key
        if self._frame_sort is not None and self._frame_sort[0] > self.order_serial:
            p_serial, p_cam, p_size = self._frame_sort
            res = self._prefetcher.take(p_cam, p_size)
            if res is not None:
                serial, made_for = p_serial, order_key(p_cam, p_size)
        self._sorter().prefetch(cam, size)
        self._frame_sort = (self.camera_serial, cam, size)
        return res, serial, made_for

    def begin(self, scale: int = 1) -> OrderRequest:
        """GUI thread: the order to make next, for the renderer's camera and size now (``scale`` > 1: asked for
        during an interaction; the order is the same). A caller that makes the orders on a worker from now on
        (``compute``) keeps them off the GUI thread: renders reuse the newest order (``reuse_order``)."""
        self.reuse_order = True
        cam = self._camera()
        size = window_size(self.renderer)
        key = order_key(cam, size)
        serial = self.camera_serial + (key != self._frame_key)   # a camera not drawn yet: the next frame's
        return {"camera": cam, "size": size, "key": key, "topo": self.topo, "preview": scale > 1, "serial": serial,
                "have": self._sorted is not None and key == self._sorted_key, "prefetcher": self._prefetcher}

    def compute(self, request: OrderRequest,
                progress: Optional[ProgressCallback] = None) -> tuple[Optional[SortResult]]:
        """Any thread: the visibility order for ``begin``'s camera (``volviz.unstructured.sort``); None when the
        volume has it already (e.g. a transfer-function edit asked for a new image)."""
        # heavy: the sort's Numba kernels and SciPy, loaded only when a PT order is computed
        from volviz.unstructured.sort import visibility_order

        if request["have"]:
            return (None,)
        pre = request.get("prefetcher")
        res = None if pre is None else pre.take(request["camera"], request["size"], consume=False)
        if res is not None:        # a frame of a drag started this camera's sort (``_follow``): no second sort
            return (res,)
        return (visibility_order(request["topo"], request["camera"], request["size"], self.sort, self.nonconvex),)

    def finish(self, request: OrderRequest, result: Optional[SortResult]) -> None:
        """GUI thread: draw with ``compute``'s order from the next render on: exact for its camera, and with
        ``reuse_order`` the newest order for any other (during an interaction the camera has moved on meanwhile)."""
        if result is None or request["topo"] is not self.topo or request.get("serial", 0) < self.order_serial:
            return                 # none, of another mesh, or older than the order drawn now
        self._sorted, self._cycles, self._sorted_key = result.order, int(result.cycles), request["key"]
        self.order_serial = request.get("serial", self.order_serial)
        self._recull = True

    def prefetch(self, camera: Camera, size: tuple[int, int] | None = None) -> None:
        """Sort for ``camera`` (the next frame's; ``size`` defaults to the renderer's) on a background worker, so
        that the render for that camera skips the sort (``volviz.unstructured.prefetch``; another camera sorts as
        usual)."""
        self._sorter().prefetch(camera, size if size is not None else window_size(self.renderer))

    def _close_sorter(self) -> None:
        """Stop the background sorter (the volume's ``remove``)."""
        if self._prefetcher is not None:
            self._prefetcher.close()
            self._prefetcher = None
