"""The natural scene in a PyVista plotter, CPU backend (Roettger Ch. 10-11 images made by ``volviz.nature``):
the terrain's C-LOD mesh as a textured VTK mesh (the baked color map, lighting off, so it matches the CPU image), the
sky dome around the eye, and the fog and cloud volumes as one screen-space RGBA overlay in front (the terrain
occlusion is already in it, from the CPU terrain z-buffer): a premultiplied texture on a quad spanning the viewport,
so that an image of any size covers it (a preview smaller than the window, a frame drawn at a reduced size).
``NatureView.update(camera)`` recomputes the terrain LOD mesh and the overlay for a camera; the app does it in the
background (``begin`` / ``compute`` / ``finish``).
``volviz.render.gl_nature.GLNatureView`` is the GPU backend with the same calls; what both share (terrain, sky, the
clipping range, ``begin``) is ``NatureSceneView``, generic in the frame its ``compute`` makes besides the terrain mesh
(the CPU's overlay image, the GPU's vertex buffers).

``build_nature_components`` builds a view from a session's terrain / fog / clouds / sky components.
"""
from __future__ import annotations

import weakref
from abc import ABC, abstractmethod
from typing import TYPE_CHECKING, Any, Callable, Generic, Literal, Optional, Sequence, TypeVar, Union

import numpy as np

from volviz.model.camera import Camera
from volviz.nature.nature_scene import NatureScene, scene_from_components
from volviz.nature.raster import render_terrain
from volviz.nature.sky import sky_dome_mesh
from volviz.render.backend import plotter_gl_info
from volviz.render.framing import nature_bounds

if TYPE_CHECKING:   # type-only imports for the signatures
    import pyvista as pv

    from volviz.jobs import ProgressCallback
    from volviz.nature.terrain import TerrainMesh
    from volviz.render.framing import Bounds
    from volviz.scene.datasets import LoadedDataset
    from volviz.session import CameraState, Component


#: a natural-scene view's request: (camera, image size (width, height), preview scale)
NatureRequest = tuple["Camera", tuple[int, int], int]
#: what a natural-scene view's ``compute`` makes besides the terrain mesh and the statistics, and its ``finish``
#: shows: ``NatureView``'s overlay image, ``GLNatureView``'s ``GLNatureFrame``
FrameT = TypeVar("FrameT")

PREVIEW_TRIANGLES = 60_000   # terrain triangles of a frame drawn while the camera moves (~60 ms on llvmpipe)

class NatureSceneView(ABC, Generic[FrameT]):
    """A ``NatureScene`` inside a PyVista plotter, what both backends share: the terrain mesh, the sky dome, the
    clipping range, ``begin`` and ``update``; ``compute`` and ``finish`` are the backend's (``NatureView``,
    ``volviz.render.gl_nature.GLNatureView``), of its own frame type."""

    kind: Literal["nature"] = "nature"
    backend: str   # the backend's: "cpu" or "gpu"
    job = ("nature", "natural scene")  # the app's key for its updates, and what its worker makes
    camera_dependent = True

    def bounds(self) -> Optional[Bounds]:
        """The terrain's and the clouds' box (``volviz.render.framing.nature_bounds``; not the sky dome's)."""
        return nature_bounds(self.scene)

    def __init__(self, plotter: Any, scene: NatureScene, size: tuple[int, int] | None = None,
                 filter_texture: bool | None = None, full: bool = False) -> None:
        """``filter_texture``: mip-map the terrain's color map (``_filtered_texture``); None: on a hardware OpenGL
        driver, not on a software rasteriser, where it costs more than it is worth (``texture_filtering``).
        ``full``: the reference view, every terrain triangle, prism and non-empty cloud cell (no LOD)."""
        # heavy: PyVista (about 180 modules), loaded only when a nature view is made
        import pyvista as pv

        self.plotter = plotter
        self.scene = scene
        scene.finalize()
        self.size = size
        self.full = bool(full)
        self.terrain_actor: Any = None
        self.sky_actor: Any = None
        self._overlay_actor: Any = None
        self._overlay_image: Any = None
        self._texture: Any = None
        self._near = 0.1
        self._mesh = None
        self.last_stats: dict[str, float] = {}
        self.shown_scale = 1          # the preview scale of the overlay shown (``compute``)
        self.preview_detail = 0.25    # the C-LOD resolution factor of previews, fitted to PREVIEW_TRIANGLES
        self._coarse: Any = None      # a full-size frame's terrain at preview detail: drawn from the first move on
        img = scene.texture_image()
        if scene.terrain is not None and img is not None:
            self._texture = pv.Texture(img)
            if texture_filtering(plotter) if filter_texture is None else filter_texture:
                _filtered_texture(self._texture)
            b = scene.terrain.bounds()
            radius = 3.0 * max(b[1] - b[0], b[3] - b[2])
            self._near = max(1e-3 * max(b[1] - b[0], b[3] - b[2]), 0.1)
        else:
            self._texture = None
            radius = 3000.0
        self.dome_radius = self._base_dome_radius = radius
        dome = sky_dome_mesh(radius, (0.0, 0.0, 0.0))  # moved to the eye by ``update``: the sky is at infinity
        if scene.sky is not None:
            sky_img = np.clip(scene.sky * 255.0, 0, 255).astype(np.uint8)
        else:  # the CPU gradient of ``render_sky`` as a polar texture (rows: zenith at the top, horizon at the bottom)
            zen, hor = np.array([0.32, 0.5, 0.85]), np.array([0.78, 0.85, 0.95])
            t = np.sqrt(np.linspace(1.0, 0.0, 256))[:, None, None]
            grad = np.broadcast_to(hor + (zen - hor) * t, (256, 4, 3))
            sky_img = np.ascontiguousarray(np.clip(grad * 255.0 + 0.5, 0, 255).astype(np.uint8))
        sky = pv.Texture(sky_img)
        # clamped, not repeated: at the horizon row (v = 0) a repeating texture blended in the zenith's colour, a
        # darker line across the whole sky
        sky.repeat = False
        sky.edge_clamp = True
        self.sky_actor = plotter.add_mesh(dome, texture=sky, lighting=False, name="nature-sky", render=False)
        # VTK's own fit of the clipping range (each fly step, each drag) is replaced by the view's (``_fit_clipping``)
        self._clip_observer: Optional[int] = plotter.renderer.AddObserver("ResetCameraClippingRangeEvent",
                                                                          _refit(weakref.ref(self)))

    def _camera(self) -> Camera:
        self._fit_clipping()
        return Camera.from_pyvista(self.plotter.camera)

    def _fit_dome(self, eye: Any) -> None:
        """Centre the sky dome on the eye (the sky is at infinity) and grow it to twice the distance from the eye to
        the farthest corner of the terrain, so that it never hides the terrain however far the camera backs away (a
        camera framed on the whole terrain sits more than the dome's base radius away from its far side)."""
        if self.sky_actor is None:
            return
        self.sky_actor.SetPosition(*np.asarray(eye, dtype=np.float64))
        if self.scene.terrain is None:
            return
        b = self.scene.terrain.bounds()
        corners = np.array([[x, y, z] for x in b[0:2] for y in b[2:4] for z in b[4:6]], dtype=np.float64)
        far = float(np.linalg.norm(corners - np.asarray(eye, dtype=np.float64), axis=1).max())
        scale = max(1.0, 2.0 * far / self._base_dome_radius)
        self.sky_actor.SetScale(scale, scale, scale)
        self.dome_radius = self._base_dome_radius * scale

    def clipping_range(self, eye: Sequence[float]) -> tuple[float, float]:
        """The view's near and far planes for an eye at ``eye``: the near plane at 1e-3 of the terrain's extent (as
        ``volviz render``'s camera, ``_as_camera``), the far one just beyond the sky dome. A function of the scene,
        the eye and the dome alone: VTK's fit to the props' bounds put the near plane at 1e-3 of a far plane that
        depended on where the dome stood (about 6.4 units on Yukon, where ``volviz render`` had 1.0), and a flight
        that ended a few terrain cells from a hillside showed it cut open (issue #28;
        docs/bench/docstring-figures.md)."""
        centre = np.asarray(self.sky_actor.GetPosition() if self.sky_actor is not None else eye, dtype=np.float64)
        offset = float(np.linalg.norm(np.asarray(eye, dtype=np.float64) - centre))
        return self._near, 1.05 * (self.dome_radius + offset)

    def _fit_clipping(self, given: Optional[tuple[float, float]] = None) -> None:
        """Set the plotter camera's clipping range to the view's (``clipping_range``), whatever set it before: VTK's
        fit to the props' bounds (each fly step, each drag), or a session camera applied before any actor existed
        (VTK's default range 0.01 .. 1000.01, whose far plane cut the dome away so the background showed instead of
        the sky). ``given``: a caller's camera range (``begin(camera)``), kept where it holds the dome and its near
        plane is not far below the view's. The renderer's VTK camera, not ``plotter.camera``: PyVista frames the
        scene on its first read of an unset camera, which refits the range and calls this again."""
        camera = self.plotter.renderer.GetActiveCamera()
        near, far = self.clipping_range(camera.GetPosition())
        if given is not None:
            near, far = (given[0] if given[0] >= 0.5 * near else near), max(given[1], far)
        camera.SetClippingRange(near, far)

    def update(self, camera: Optional[Camera] = None) -> dict[str, float]:
        """Re-triangulate the terrain and re-render the overlay for ``camera`` (default: the plotter's camera), now.
        An app renders it in the background instead: ``begin`` (GUI thread), ``compute`` (any thread), ``finish``
        (GUI thread)."""
        request = self.begin(camera)
        return self.finish(request, *self.compute(request))

    def begin(self, camera: Optional[Camera] = None, scale: int = 1) -> NatureRequest:
        """GUI thread: the view to compute (``camera`` or the plotter's, the image size and the preview ``scale``,
        see ``compute``); moves the sky dome to the eye (the sky is at infinity)."""
        self._fit_dome(camera.position if camera is not None else self.plotter.camera.position)
        cam = camera or self._camera()     # after the dome moved: the clipping range depends on where it stands
        coarse, self._coarse = self._coarse, None
        if scale > 1 and coarse is not None:  # the camera starts moving: draw the shown view's coarse terrain at once
            self._show_terrain(coarse.to_pyvista())
        if camera is not None:
            camera.apply_to(self.plotter.camera)
            self._fit_clipping(camera.clipping_range)  # the VTK side only: ``cam`` keeps the caller's range
        w, h = self.size or (int(self.plotter.window_size[0]), int(self.plotter.window_size[1]))
        return cam, (w, h), max(1, int(scale))

    @abstractmethod
    def compute(self, request: NatureRequest, progress: Optional[ProgressCallback] = None
                ) -> tuple[Optional[TerrainMesh], FrameT, dict[str, float]]:
        """Any thread: the terrain's C-LOD mesh for ``request`` (None without terrain), the backend's frame and the
        statistics."""

    @abstractmethod
    def finish(self, request: NatureRequest, mesh: Optional[TerrainMesh], frame: FrameT,
               stats: dict[str, float]) -> dict[str, float]:
        """GUI thread: show a ``compute`` result; returns its statistics."""

    def _show_terrain(self, poly: Any) -> None:
        """The C-LOD terrain mesh (VTK poly data; None: keep the shown one) as the textured terrain actor. A scene
        without terrain takes the terrain of the view it replaced (still shown until this first frame) off the
        plotter. While no triangle is in view (e.g. the camera looks at the sky) before the first one, no actor is
        made (PyVista refuses empty meshes)."""
        if poly is not None:
            if self.terrain_actor is None and poly.n_points == 0:
                return
            if self.terrain_actor is None:
                self.terrain_actor = self.plotter.add_mesh(poly, texture=self._texture, lighting=False,
                                                           name="nature-terrain", render=False)
            else:
                self.terrain_actor.mapper.SetInputData(poly)
            self._mesh = poly
        elif self.terrain_actor is None:
            self.plotter.remove_actor("nature-terrain", render=False)

    def remove(self) -> None:
        """Take the view's actors (sky, terrain, overlay) and its clipping observer out of the plotter."""
        if self._clip_observer is not None and self.plotter.renderer is not None:
            self.plotter.renderer.RemoveObserver(self._clip_observer)
        self._clip_observer = None
        for name in ("nature-sky", "nature-terrain", "nature-overlay"):
            self.plotter.remove_actor(name, render=False)
        self.terrain_actor = self._overlay_actor = self._overlay_image = None


class NatureView(NatureSceneView[np.ndarray]):
    """The CPU backend of the natural-scene view: the fog and clouds rendered by ``volviz.nature`` into one
    screen-space overlay image in front of the terrain (module docstring); ``volviz.render.gl_nature.GLNatureView``
    is the GPU one."""

    backend = "cpu"

    def compute(self, request: NatureRequest, progress: Optional[ProgressCallback] = None
                ) -> tuple[Optional[TerrainMesh], np.ndarray, dict[str, float]]:
        """Any thread (one at a time): the C-LOD terrain mesh (None without terrain; ``finish`` makes its VTK poly data
        on the GUI thread: a VTK object made on a worker while the GUI thread renders can deadlock the two, the
        worker holding the GIL in VTK's garbage collector while a render collects a PyVista object that needs the
        GIL, as a drag over Mount St. Helens did), the fog and cloud overlay as 8-bit premultiplied RGBA rows
        bottom-up, and the statistics. ``progress(fraction, message)``
        is called between the stages (a job runner cancels there). A preview (``scale`` > 1, e.g. while the camera
        moves) renders the fog and clouds at 1/scale of the size in each direction (OpenGL magnifies them:
        ``_set_overlay``) over a coarser terrain of about ``PREVIEW_TRIANGLES`` triangles (the C-LOD resolution
        scaled by ``preview_detail``, refitted after each preview): the full mesh, half a million triangles on Yukon,
        is slow to draw on a software OpenGL, and each frame drawn while flying blocked the window that long
        (docs/bench/docstring-figures.md). The clouds' levels of detail are those of the full size."""
        cam, size, scale = request
        preview = scale > 1 and not self.full
        mesh = self._preview_mesh(cam, size) if preview else self.scene.terrain_mesh(cam, size, full=self.full)
        if scale > 1:
            size = (max(1, size[0] // scale), max(1, size[1] // scale))
        w, h = size
        stats: dict[str, float] = {}
        depth = np.full((h, w), np.inf)
        if mesh is not None:
            if progress is not None:
                progress(0.3, "terrain")
            if not preview and not self.full:   # the view's preview terrain, drawn from the next move on (``begin``)
                coarse = self._preview_mesh(cam, size)
                self._coarse = coarse if coarse is not None and coarse.n_triangles else None
            depth, _ = render_terrain(mesh.points, mesh.triangles, mesh.tcoords, cam, size, self.scene._pyramid)
            stats["terrain_triangles"] = float(mesh.n_triangles)
        if progress is not None:
            progress(0.5, "fog and clouds")
        overlay = _overlay_rgba(self.scene.render_volumes(cam, size, mesh, depth, full=self.full, stats=stats))
        return mesh, overlay, stats

    def _preview_mesh(self, cam: Any, size: tuple[int, int]) -> Any:
        """The terrain at ``preview_detail``, refitted to ``PREVIEW_TRIANGLES`` (C-LOD's count grows about as
        C^0.9): once more at once when it is off by more than half."""
        for _ in range(2):
            mesh = self.scene.terrain_mesh(cam, size, detail=self.preview_detail)
            if mesh is None or mesh.n_triangles == 0:
                return mesh
            ratio = PREVIEW_TRIANGLES / mesh.n_triangles
            detail = float(np.clip(self.preview_detail * ratio ** 1.1, 0.01, 1.0))
            if 0.67 < ratio < 1.5 or detail == self.preview_detail:
                self.preview_detail = detail
                return mesh
            self.preview_detail = detail
        return mesh

    def finish(self, request: NatureRequest, mesh: Optional[TerrainMesh], overlay: np.ndarray,
               stats: dict[str, float]) -> dict[str, float]:
        """GUI thread: show a ``compute`` result (terrain mesh, made VTK poly data here, and overlay image)."""
        self._show_terrain(mesh.to_pyvista() if mesh is not None else None)
        self._set_overlay(overlay, smooth=int(request[2]) > 1)
        self.last_stats = stats
        self.shown_scale = int(request[2])
        return stats

    def _set_overlay(self, overlay: np.ndarray, smooth: bool = False) -> None:
        """Show an overlay image of ``_overlay_rgba`` (8-bit premultiplied RGBA, rows bottom-up) in front of the scene,
        over the whole viewport whatever the image's size (``_viewport_quad``). ``smooth``: filtered linearly (a
        preview smaller than the viewport); at the viewport's size each pixel shows its texel either way. A preview
        uploads 1/scale² of the pixels and needs no magnification on the CPU (a magnified preview cost the worker a
        resize and the GUI thread a full-size copy and upload; docs/bench/docstring-figures.md)."""
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import numpy_to_vtk, vtk

        h, w = overlay.shape[:2]
        if self._overlay_image is None:
            self._overlay_image = vtk.vtkImageData()
            self._overlay_actor = _viewport_quad(self._overlay_image)
            self.plotter.add_actor(self._overlay_actor, name="nature-overlay", reset_camera=False, render=False)
        img = self._overlay_image
        img.SetDimensions(w, h, 1)
        arr = numpy_to_vtk(overlay.reshape(-1, 4), deep=True)
        arr.SetNumberOfComponents(4)
        img.GetPointData().SetScalars(arr)
        img.Modified()
        self._overlay_actor.GetTexture().SetInterpolate(bool(smooth))


def _refit(view: weakref.ref[NatureSceneView[Any]]) -> Callable[..., None]:
    """The observer that sets the view's clipping range after VTK fitted its own (the view held weakly: the
    renderer outlives it)."""

    def refit(*args: Any) -> None:
        shown = view()
        if shown is not None:
            shown._fit_clipping()

    return refit


#: anisotropic filtering of the terrain texture: none (VTK's default is 4), as the CPU raster's isotropic mip-map
ANISOTROPY = 1.0


def texture_filtering(plotter: pv.BasePlotter) -> bool:
    """Whether the terrain texture is mip-mapped in ``plotter`` by default: on a hardware OpenGL driver (free there),
    not on a software rasteriser (``volviz.render.backend``), where the mip-mapped terrain nearly doubles the time of
    a frame and of the first one (making the mip-maps) on the GUI thread (docs/bench/docstring-figures.md);
    unfiltered, the terrain shimmers as the camera moves (``_filtered_texture``)."""
    return not plotter_gl_info(plotter).software


def _filtered_texture(texture: Any) -> Any:
    """The terrain's color map filtered as the CPU raster shades it (``volviz.nature.raster``: an isotropic mip-map
    pyramid): mip-mapped and trilinear. Unfiltered, every small camera step re-sampled the map's texels differently:
    the views changed far more per step than the full-resolution reference (a shimmer no LOD setting could remove)
    and stood farther from it; filtered, about the reference's change per step (``volviz bench nature``).
    Anisotropic filtering is sharper at grazing angles but farther from the reference
    (docs/bench/docstring-figures.md)."""
    texture.SetMipmap(True)
    texture.InterpolateOn()
    texture.SetMaximumAnisotropicFiltering(ANISOTROPY)
    return texture


def _viewport_quad(image: Any) -> Any:
    """A 2D actor showing ``image`` (vtkImageData of 8-bit premultiplied RGBA) as a texture on a quad spanning the
    viewport (corners in normalized viewport coordinates, texture coordinates 0..1: at the viewport's size the
    centre of pixel i samples texel i exactly), blended with (ONE, ONE_MINUS_SRC_ALPHA) (``PremultipliedAlpha``), so
    no colour bleeds from transparent texels where OpenGL filters it."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import numpy_to_vtk, vtk

    quad = vtk.vtkPolyData()
    points = vtk.vtkPoints()
    points.SetData(numpy_to_vtk(np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], np.float32), deep=True))
    quad.SetPoints(points)
    cells = vtk.vtkCellArray()
    cells.InsertNextCell(4, [0, 1, 2, 3])
    quad.SetPolys(cells)
    quad.GetPointData().SetTCoords(numpy_to_vtk(np.array([[0, 0], [1, 0], [1, 1], [0, 1]], np.float32), deep=True))
    corners = vtk.vtkCoordinate()
    corners.SetCoordinateSystemToNormalizedViewport()
    mapper = vtk.vtkPolyDataMapper2D()
    mapper.SetInputData(quad)
    mapper.SetTransformCoordinate(corners)
    texture = vtk.vtkTexture()
    texture.SetInputData(image)
    texture.SetColorModeToDirectScalars()
    texture.PremultipliedAlphaOn()
    texture.InterpolateOff()
    texture.RepeatOff()
    texture.EdgeClampOn()
    actor = vtk.vtkTexturedActor2D()
    actor.SetMapper(mapper)
    actor.SetTexture(texture)
    return actor


def _overlay_rgba(overlay: np.ndarray) -> np.ndarray:
    """A premultiplied RGBA image as 8-bit premultiplied RGBA, rows bottom-up (VTK's order), for blending in front
    of the scene with (ONE, ONE_MINUS_SRC_ALPHA). Pure emission (α = 0, color > 0) is shown with α' = max(α, max
    color): C + (1 − α') B instead of C + B (error ≤ α' B)."""
    alpha = np.clip(np.maximum(overlay[..., 3], overlay[..., :3].max(axis=-1)), 0.0, 1.0)
    color = np.minimum(np.clip(overlay[..., :3], 0.0, 1.0), alpha[..., None])
    rgba = np.concatenate([color, alpha[..., None]], axis=-1)[::-1]  # VTK rows start at the bottom
    return np.ascontiguousarray((rgba * 255.0 + 0.5).astype(np.uint8))


def build_nature_components(plotter: pv.BasePlotter, components: Sequence[Component],
                            datasets: dict[str, LoadedDataset],
                            camera: Union[Camera, CameraState, None] = None,
                            size: tuple[int, int] | None = None) -> NatureView:
    """Add the session's terrain / fog / clouds / sky components to ``plotter`` and render the first overlay for
    ``camera`` (a ``volviz.model.camera.Camera``, a ``volviz.session.CameraState`` or None for the
    plotter's). Call ``view.update()`` again after the camera moves."""
    scene = scene_from_components(components, datasets)
    view = NatureView(plotter, scene, size)
    cam = _as_camera(camera, scene) if camera is not None else None
    view.update(cam)
    return view


def _as_camera(camera: Any, scene: NatureScene) -> Any:
    if isinstance(camera, Camera):
        return camera
    near, far = 5.0, 20000.0
    if scene.terrain is not None:
        ex = max(scene.terrain.extent)
        near, far = max(ex * 1e-3, 0.1), ex * 20.0
    return Camera(camera.position, camera.focal_point, camera.view_up, camera.view_angle,
                  clipping_range=(near, far))
