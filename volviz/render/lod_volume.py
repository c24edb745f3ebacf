"""Multiresolution rendering of a compressed volume in a PyVista plotter (Guthe §2.3.6 block rendering).

A ``LodVolume`` owns a ``volviz.regular.lod.LodTree`` (the wavelet octree of a ``.vvz`` file) and draws the blocks
chosen for the current camera:

    lod = LodVolume(plotter, LodTree("head.vvz"), tf, budget=256)      # renderer="volviz" (default) or "vtk"
    lod.update()                      # select for the plotter's camera, decode through the LRU cache, draw
    lod.stats                         # blocks, levels, decode / select / render seconds, transparent blocks skipped

Two renderers:

- ``"volviz"`` (default): our one-pass ray caster over the selected blocks (``volviz.regular.raycast``: an index
  grid finds a sample's block in O(1), steps grow with the block's level, separable pre-integration, transparent
  blocks leapt over, early ray termination). Its premultiplied image is drawn by ``volviz.render.image_overlay``, as
  the PT volumes are: the opaque scene is rendered with every volviz overlay off, its z-buffer is read and turned
  into a per-pixel depth limit for the rays (skipped when the renderer has no visible actor), and the image goes
  into an overlay renderer on a higher layer with (SRC_ALPHA, ONE_MINUS_SRC_ALPHA) blending (8-bit round trip ≤
  1/255). The overlay joins the plotter's list of volviz overlays, so PT volumes and LOD volumes hide each other
  while reading depth. Mapper clipping planes (``self.mapper``, set by the controller) clip the rays at the next
  draw. Frame times against the VTK path: ``docs/bench/compression-animation.md``.
- ``"vtk"``: one ``vtkVolume`` whose ``vtkMultiBlockVolumeMapper`` draws each block as its own image with its own
  spacing, sorted back to front by VTK. Each block is a pass of its own, so the frame time grows with the number of
  blocks (``docs/bench/compression-animation.md``).

Blocks carry a one-voxel overlap with their +x/+y/+z neighbours of the same level (``LodTree.block``), so trilinear
interpolation is continuous across the boundary of two blocks of one level: the image of a selection that is one
level everywhere matches that level rendered as one volume (measured in ``tests/test_render_lod.py``). Where levels
meet, the coarser block's samples differ from the finer one's by the node's approximation error (the quantity the
selection bounds, Eq. 2.7). ``select`` and ``decode`` are Qt-free and thread-safe, so the app can run them in the
job runner and call ``show`` on the GUI thread; ``update`` does all three. With the default renderer ``camera()``
(GUI thread) also captures the view a ray cast needs from the plotter (the full camera, the opaque scene's depth
when there is visible geometry, the clipping planes) and ``decode`` ray casts the selection for that view, so
``show`` only uploads the image if camera, projection, size, planes and TF are unchanged; otherwise ``show`` ray
casts on the GUI thread. ``self.volume`` (a ``vtkVolume``) carries the visibility in both modes (with ``"volviz"``
it is not in the renderer; its visibility switches the overlay).
"""
from __future__ import annotations

import threading
import time
from typing import TYPE_CHECKING, Any, Literal, Optional, TypedDict, Union

import numpy as np

from volviz.model import vec3
from volviz.model.camera import Camera
from volviz.regular.lod import Block, LodCamera, LodTree, Selection
from volviz.regular.raycast import STEP, pack_blocks, render_blocks, segment_table
from volviz.render.clipping import clip_vtk_prop
from volviz.render.image_overlay import ImageOverlay, unpremultiply_rgba8, zbuffer_to_depth
from volviz.render.vtk_scene import update_volume_property, vtk_volume_property
from volviz.scene.lod import lod_bounds

if TYPE_CHECKING:   # type-only imports for the signatures
    import pyvista as pv

    from volviz.jobs import ProgressCallback
    from volviz.model.clip import ClipSettings
    from volviz.optics.transfer_function import TransferFunction
    from volviz.render.vtk_facade import vtkCamera

RENDERERS = ("volviz", "vtk")

__all__ = ["LodRequest", "LodVolume", "RENDERERS", "lod_camera"]


class LodRequest(TypedDict):
    """A LOD view's request (``LodVolume.begin``, ``volviz.render.views.View``): the camera and viewport to select
    for, the block budget, and whether it is a preview while the camera moves."""

    camera: LodCamera
    budget: int
    preview: bool


def lod_camera(vtk_camera: Union[pv.Camera, vtkCamera], size: tuple[int, int]) -> LodCamera:
    """The LOD selection's pinhole camera for a ``vtkCamera``/``pyvista.Camera`` and an image ``size`` (W, H)."""
    return LodCamera(eye=vec3(vtk_camera.GetPosition()),
                     target=vec3(vtk_camera.GetFocalPoint()),
                     up=vec3(vtk_camera.GetViewUp()), fov_y=float(vtk_camera.GetViewAngle()),
                     width=int(size[0]), height=int(size[1]))


def _image(block: Block) -> Any:
    """A vtkImageData of one block (samples at origin + spacing * index, x fastest)."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import numpy_to_vtk, vtk

    img = vtk.vtkImageData()
    img.SetDimensions(*block.data.shape)
    img.SetOrigin(*block.origin)
    img.SetSpacing(*block.spacing)
    arr = numpy_to_vtk(np.ascontiguousarray(block.data.ravel(order="F")), deep=True)
    arr.SetName("scalars")
    img.GetPointData().SetScalars(arr)
    return img


class _Overlay(ImageOverlay):
    """The ray caster's image over the plotter's scene: ``volviz.render.image_overlay`` (the PT volumes' mechanism:
    same layer scheme, same sibling list, same straight-alpha upload), taking premultiplied float images."""

    def depth(self, size: tuple[int, int]) -> Optional[np.ndarray]:
        """Eye-space depth of the opaque scene (H, W), inf where none (with the clipping range of the render that
        made it); None when the renderer has no visible actor (nothing can hide the volume, and the extra render +
        read-back is skipped)."""
        if self.plotter.renderer.VisibleActorCount() == 0:
            return None
        z, _ = self.opaque_buffers(size)
        cam = self.plotter.renderer.GetActiveCamera()
        return zbuffer_to_depth(z, cam.GetClippingRange(), bool(cam.GetParallelProjection()))

    def show_image(self, img: np.ndarray, visible: bool) -> None:
        """Show a premultiplied float RGBA image (H, W, 4), row 0 at the top."""
        self.show(unpremultiply_rgba8(img), visible)


def _mapper_planes(mapper: Any) -> Optional[np.ndarray]:
    """The mapper's clipping planes as (k, 4) rows (n, w) with n . X + w >= 0 kept (VTK keeps the normal's side)."""
    planes = mapper.GetClippingPlanes()
    if planes is None or planes.GetNumberOfItems() == 0:
        return None
    rows = []
    for i in range(planes.GetNumberOfItems()):
        p = planes.GetItem(i)
        n = np.asarray(p.GetNormal(), float)
        rows.append([*n, -float(n @ np.asarray(p.GetOrigin(), float))])
    return np.asarray(rows)


class LodVolume:
    """A LOD-rendered compressed volume attached to a plotter (see the module docstring); the view kind "lod" of
    ``volviz.render.views`` (CPU only)."""

    backend = "cpu"

    def __init__(self, plotter: Any, tree: LodTree, tf: Any, budget: int = 256, mode: str = "tf",
                 opacity: float = 1.0, renderer: str = "volviz", step: Optional[float] = None) -> None:
        """``renderer``: "volviz" (our ray caster) or "vtk" (vtkMultiBlockVolumeMapper); ``step``: the ray
        caster's sample distance in voxels of each block's level (default ``volviz.regular.raycast.STEP``)."""
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        if renderer not in RENDERERS:
            raise ValueError(f"LOD renderer must be one of {RENDERERS}, got {renderer!r}")
        self.plotter, self.tree, self.tf = plotter, tree, tf
        self.budget, self.mode, self.opacity = int(budget), mode, float(opacity)

        self.renderer, self.step = renderer, float(STEP if step is None else step)
        self.mapper = vtk.vtkMultiBlockVolumeMapper()
        self.volume = vtk.vtkVolume()
        self.volume.SetMapper(self.mapper)
        self.volume.SetProperty(vtk_volume_property(tf, opacity))
        self._images: dict[Any, Any] = {}               # block key -> vtkImageData / Block (reused while selected)
        self.selection: Optional[Selection] = None
        self.stats: dict[str, Any] = {}
        self.image: Optional[np.ndarray] = None         # "volviz": the last premultiplied image (H, W, 4)
        self.depth: Optional[np.ndarray] = None         # "volviz": its per-pixel depth limit (None: no geometry)
        self._pool: Any = None
        self._table: Any = None
        self._table_key: Any = None
        self._overlay: Optional[_Overlay] = None
        self._lock = threading.RLock()                  # guards the dicts below, _images and the table cache
        self._views: dict[int, tuple[Any, ...]] = {}    # id(LOD camera) -> its view (``camera``; last few)
        self._cameras: dict[int, tuple[Selection, Any]] = {}            # id(selection) -> its view (last few)
        self._prepared: dict[int, tuple[Any, ...]] = {}                  # id(selection) -> image made by decode
        if renderer == "vtk":
            plotter.renderer.AddVolume(self.volume)
        else:
            self._overlay = _Overlay(plotter)
            self.volume.AddObserver("ModifiedEvent", self._visibility_changed)

    def _visibility_changed(self, *_: Any) -> None:
        if self._overlay is not None:
            self._overlay.renderer.SetDraw(bool(self.volume.GetVisibility()) and self.image is not None)

    kind: Literal["lod"] = "lod"
    job = ("lod", "level of detail")  # the app's key for its updates, and what its worker makes
    coarse_first = True  # a settled camera first shows a coarse selection (``begin(scale=2)``), then the full one
    while_moving = False  # VTK draws the selected blocks for any camera: nothing to re-make while it moves
    camera_dependent = True

    @property
    def prop(self) -> LodVolume:
        return self

    @property
    def visible(self) -> bool:
        return bool(self.volume.GetVisibility())

    @visible.setter
    def visible(self, on: bool) -> None:
        self.volume.SetVisibility(bool(on))

    def set_tf(self, tf: TransferFunction, opacity: float = 1.0) -> None:
        """A new TF and opacity (``volviz.render.views.ComponentView``): the current selection is drawn again; the
        caller re-selects (``update``, or ``begin`` / ``compute`` / ``finish``: the selection depends on the TF)."""
        self.opacity = float(opacity)
        self.set_transfer_function(tf)

    def set_clip(self, clip: ClipSettings) -> bool:
        """The mapper's clipping planes, which the ray caster reads at the next selection's draw (True: nothing for
        the caller to cut)."""
        clip_vtk_prop(self.volume, clip)
        return True

    def bounds(self) -> tuple[float, float, float, float, float, float]:
        return lod_bounds(self.tree)

    def set_transfer_function(self, tf: TransferFunction) -> None:
        """A new TF (and the current ``opacity``); with our renderer the current selection is drawn again."""
        self.tf = tf
        update_volume_property(self.volume.GetProperty(), tf, self.opacity)
        if self.renderer == "volviz" and self._pool is not None:
            self.draw()

    def _lod_camera(self) -> LodCamera:
        w, h = (int(v) for v in self.plotter.ren_win.GetSize())
        return lod_camera(self.plotter.renderer.GetActiveCamera(), (w, h))

    def camera(self) -> LodCamera:
        """GUI thread: the plotter's current camera and viewport size, for ``select`` on another thread. With our
        renderer it also captures what a ray cast of that view needs from the plotter (the full camera, the opaque
        scene's depth when there is visible geometry, the clipping planes), so that ``decode`` can ray cast on the
        worker too."""
        cam = self._lod_camera()
        if self.renderer == "volviz" and self._overlay is not None and self.volume.GetVisibility():
            depth = self._overlay.depth((cam.width, cam.height))
            view = (cam, Camera.from_pyvista(self.plotter.renderer.GetActiveCamera()), depth,
                    _mapper_planes(self.mapper))
            with self._lock:
                self._views[id(cam)] = view
                while len(self._views) > 4:
                    self._views.pop(next(iter(self._views)))
        return cam

    def select(self, camera: LodCamera, budget: Optional[int] = None) -> Selection:
        """Any thread: the blocks for ``camera`` under the block budget (Guthe §2.3.3; default ``self.budget``; the
        app first shows a coarse selection under a smaller budget, then refines)."""
        sel = self.tree.select(camera, self.budget if budget is None else int(budget), tf=self.tf, mode=self.mode)
        if self.renderer == "volviz":
            with self._lock:
                view = self._views.get(id(camera))
                if view is None or view[0] is not camera:
                    return sel
                self._cameras[id(sel)] = (sel, view)
                while len(self._cameras) > 4:
                    self._cameras.pop(next(iter(self._cameras)))
        return sel

    def decode(self, selection: Selection) -> list[Block]:
        """Any thread: the selected blocks' samples (decoded on demand through the tree's LRU cache). With our
        renderer, when the selection came from ``select`` for a ``camera()`` view, this also ray casts the selection
        for that view (its camera, opaque depth and clipping planes), so that ``show`` on the GUI thread only
        uploads the image (if camera, size, planes and TF are still the same)."""
        with self._lock:
            held = set(self._images)
        blocks = [self.tree.block(key) for key in selection.nodes if key not in held] if selection.nodes else []
        if self.renderer == "volviz" and selection.nodes:
            self._prepare(selection, blocks)
        return blocks

    def _effective_tf(self) -> tuple[Any, str]:
        tf = self.tf.scaled_extinction(max(self.opacity, 0.0)) if self.opacity != 1.0 else self.tf
        return tf, repr(tf.to_dict())

    def _prepare(self, selection: Selection, blocks: list[Block]) -> None:
        with self._lock:
            entry = self._cameras.get(id(selection))
            held = dict(self._images)
        if entry is None or entry[0] is not selection:
            return
        t0 = time.perf_counter()
        lod_cam, cam, depth, planes = entry[1]
        new = {b.key: b for b in blocks}
        pool = pack_blocks([new[k] if k in new else held[k] if k in held else self.tree.block(k)
                            for k in selection.nodes], self.tree.shapes[0], self.tree.origin, self.tree.spacing)
        tf, tf_key = self._effective_tf()
        t1 = time.perf_counter()
        table = self._segment_table(tf, pool)
        t2 = time.perf_counter()
        img = render_blocks(pool, tf, cam, (lod_cam.width, lod_cam.height), step=self.step, depth=depth,
                            table=table, planes=planes)
        t3 = time.perf_counter()
        with self._lock:
            self._prepared[id(selection)] = (selection, entry[1], tf_key, pool, img,
                                             {"pack_s": t1 - t0, "table_s": t2 - t1, "render_s": t3 - t2})
            while len(self._prepared) > 2:
                self._prepared.pop(next(iter(self._prepared)))

    def show(self, selection: Selection, blocks: list[Block], select_s: float = 0.0, decode_s: float = 0.0) -> None:
        """GUI thread: draw ``selection`` (``blocks`` holds the ones not drawn before); ``stats`` describe it, with
        the seconds its selection and decoding took."""
        with self._lock:
            for b in blocks:
                self._images[b.key] = _image(b) if self.renderer == "vtk" else b
            keep = set(selection.nodes)
            for key in [k for k in self._images if k not in keep]:
                del self._images[key]
            prepared = self._prepared.pop(id(selection), None)
        self.selection = selection
        self.stats = self.show_stats(selection, blocks, select_s, decode_s)
        if self.renderer == "vtk":
            # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
            from volviz.render.vtk_facade import vtk

            mb = vtk.vtkMultiBlockDataSet()
            mb.SetNumberOfBlocks(len(selection.nodes))
            for i, key in enumerate(selection.nodes):
                mb.SetBlock(i, self._images[key])
            self.mapper.SetInputDataObject(mb)
            return
        if prepared is not None and self._use_prepared(selection, prepared):
            return

        t0 = time.perf_counter()
        self._pool = pack_blocks([self._images[k] for k in selection.nodes], self.tree.shapes[0], self.tree.origin,
                                 self.tree.spacing)
        self.stats["pack_s"] = time.perf_counter() - t0
        self.draw()

    def _use_prepared(self, selection: Selection, prepared: tuple[Any, ...]) -> bool:
        """GUI thread: show the image ``decode`` made, if it is still right for the plotter (same selection,
        camera, projection, size, clipping planes and TF; visible). The opaque depth is the one captured with the
        camera (as a PT volume's image is made against the depth of its ``begin``)."""
        sel, view, tf_key, pool, img, st = prepared
        lod_cam, cam, depth, planes = view
        now = _mapper_planes(self.mapper)
        same_planes = (planes is None and now is None) or (planes is not None and now is not None
                                                            and np.array_equal(planes, now))
        vcam = self.plotter.renderer.GetActiveCamera()
        if sel is not selection or lod_cam != self._lod_camera() or tf_key != self._effective_tf()[1] \
                or bool(vcam.GetParallelProjection()) != cam.parallel \
                or (cam.parallel and float(vcam.GetParallelScale()) != float(cam.parallel_scale)) or not same_planes \
                or not self.volume.GetVisibility() or self._overlay is None:
            return False
        t0 = time.perf_counter()
        self._pool, self.image, self.depth = pool, img, depth
        self._overlay.show_image(img, True)
        self.stats.update({"renderer": "volviz", "prepared": True, "readback_s": 0.0, "draw_s": 0.0,
                           "upload_s": time.perf_counter() - t0, "size": (img.shape[1], img.shape[0]), **st})
        return True

    def _segment_table(self, tf: Any, pool: Any) -> Any:
        """The separable table for ``tf`` over the data range of every level (cached per TF)."""
        lo = min(float(self.tree._to_data(st.vmin.min())) for st in self.tree.stats)
        hi = max(float(self.tree._to_data(st.vmax.max())) for st in self.tree.stats)
        plo, phi = pool.scalar_range
        lo, hi = min(lo, plo), max(hi, phi)
        l_max = self.step * float(1 << self.tree.levels) * float(np.min(self.tree.spacing))
        key = (repr(tf.to_dict()), lo, hi, l_max)
        with self._lock:
            if key != self._table_key:
                self._table, self._table_key = segment_table(tf, (lo, hi), l_max), key
            return self._table

    def draw(self) -> Optional[np.ndarray]:
        """GUI thread ("volviz" renderer): ray cast the shown selection for the plotter's current camera, against
        the opaque scene's depth, and put the image on the overlay; returns the premultiplied image."""
        if self._pool is None or self._overlay is None:
            return None

        t0 = time.perf_counter()
        w, h = (int(v) for v in self.plotter.ren_win.GetSize())
        cam = Camera.from_pyvista(self.plotter.renderer.GetActiveCamera())
        visible = bool(self.volume.GetVisibility())
        depth = self._overlay.depth((w, h)) if visible else None
        t1 = time.perf_counter()
        tf = self._effective_tf()[0]
        table = self._segment_table(tf, self._pool)
        t2 = time.perf_counter()
        img = render_blocks(self._pool, tf, cam, (w, h), step=self.step, depth=depth, table=table,
                            planes=_mapper_planes(self.mapper)) if visible else np.zeros((h, w, 4), np.float32)
        t3 = time.perf_counter()
        self.image, self.depth = img, depth
        self._overlay.show_image(img, visible)
        t4 = time.perf_counter()
        self.stats.update({"renderer": "volviz", "prepared": False, "readback_s": t1 - t0, "table_s": t2 - t1,
                           "render_s": t3 - t2, "upload_s": t4 - t3, "draw_s": t4 - t0, "size": (w, h)})
        return img

    def begin(self, scale: int = 1) -> LodRequest:
        """GUI thread: the selection to make for the plotter's camera now (``volviz.render.views.View``); a preview
        (``scale`` > 1, while the camera moves) asks for an eighth of the block budget, as the app's coarse pass."""
        budget = max(1, self.budget // 8) if scale > 1 else self.budget
        return {"camera": self.camera(), "budget": budget, "preview": scale > 1}

    def compute(self, request: LodRequest, progress: Optional[ProgressCallback] = None
                ) -> tuple[Selection, list[Block], float, float]:
        """Any thread: the selection of ``begin``'s request and its decoded new blocks, with their seconds."""
        t0 = time.perf_counter()
        selection = self.select(request["camera"], request["budget"])
        t1 = time.perf_counter()
        blocks = self.decode(selection)
        return selection, blocks, t1 - t0, time.perf_counter() - t1

    def finish(self, request: LodRequest, selection: Selection, blocks: list[Block], select_s: float = 0.0,
               decode_s: float = 0.0) -> dict[str, object]:
        """GUI thread: draw ``compute``'s selection (``show``); returns the statistics."""
        self.show(selection, blocks, select_s, decode_s)
        return self.stats

    def update(self) -> dict[str, object]:
        """Select for the plotter's current camera, decode and draw; returns the statistics."""
        t0 = time.perf_counter()
        sel = self.select(self.camera())
        t1 = time.perf_counter()
        blocks = self.decode(sel)
        t2 = time.perf_counter()
        self.show(sel, blocks, t1 - t0, t2 - t1)
        return self.stats

    def show_stats(self, selection: Selection, blocks: list[Block], select_s: float,
                   decode_s: float) -> dict[str, object]:
        levels: dict[int, int] = {}
        for level, _ in selection.nodes:
            levels[level] = levels.get(level, 0) + 1
        return {"blocks": len(selection.nodes), "levels": dict(sorted(levels.items())), "select_s": select_s,
                "decode_s": decode_s, "new_blocks": len(blocks), "skipped_transparent": selection.skipped_transparent,
                "culled": selection.culled, "renderer": self.renderer}

    def remove(self) -> None:
        if self._overlay is not None:
            self._overlay.remove()
            self._overlay = None
        else:
            self.plotter.renderer.RemoveVolume(self.volume)
