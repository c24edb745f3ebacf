"""Many semi-transparent isosurfaces drawn by VTK's OpenGL pipeline in the transparency modes of the libMini note
§4 ("Real-Time Rendering of Multiple Iso-surfaces and Multiple Volumes"), with the note's iso-spectrum shading
("Shaded Iso-Surfaces"); the GPU counterpart of the CPU compositor ``volviz.iso.composite``.

    iso = GLIsoSurfaces(plotter, meshes, mode="4pass")   # IsoMeshes of any number of volumes
    plotter.show() / plotter.screenshot()
    iso.set_mode("3pass"); iso.remove()

``GLIsoView`` is the scene controller's isosurface view on the GPU backend (``volviz.render.backend``, view kind
"iso"): the calls of the CPU overlay ``volviz.render.iso_overlay.IsoOverlay`` (``mode``, ``set_surfaces``, ``update``,
``remove``, ``stats``, ``backend``) over a ``GLIsoSurfaces`` made again when the surfaces change.

Every pass runs over all surfaces of all volumes at once (one vertex buffer per pass, so the per-pixel sums and
products are order-independent across volumes); "2pass", "3pass", "4pass" are ordinary translucent actors, "exact"
is VTK's depth peeling in a ``PeelLayer``. The modes, the shading and the GL state each restores:
docs/gl-passes.md "gl_iso: many translucent isosurfaces (libMini note §4)"; errors against the CPU compositor and
frame times: docs/bench/gl-passes.md "gl_iso", ``docs/bench/iso.md``.
"""
from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any, Optional, Sequence

import numpy as np

from volviz.iso.composite import AMBIENT, MODES
from volviz.iso.extract import IsoMesh
from volviz.iso.spectrum import fit_spectrum
from volviz.model.extent import point_extent
from volviz.render.gl import glenum, shader_source
from volviz.render.image_overlay import hold_single_sample, release_single_sample, window_size
from volviz.render.iso_overlay import IsoModeView
from volviz.render.iso_volume_split import shown_regular_volumes
from volviz.render.peel_layer import PeelLayer
from volviz.render.volume_peeling import peel_volumes

if TYPE_CHECKING:   # type-only: VTK's classes, reached through the facade at run time; the progress callback; LOD
    from volviz.iso.lod import LodChain
    from volviz.jobs import ProgressCallback
    from volviz.render.vtk_facade import vtkPolyData

__all__ = ["GLIsoSurfaces", "GLIsoView", "iso_polydata"]

_OPAQUE, _OVER, _ATTENUATE, _BACK, _EMIT, _PEEL = range(6)
_ATTRIBUTES = ("isoNormal", "isoStyle", "isoFit")


def _oriented_triangles(m: IsoMesh) -> np.ndarray:
    """The mesh's triangles wound so that the right-hand normal agrees with the vertex normals (as composite.py orients
    the geometric normal to tell back faces), so GL's ``gl_FrontFacing`` is the CPU's front."""
    tris = np.asarray(m.triangles, np.int64).reshape(-1, 3)
    if not len(tris):
        return tris
    p, n = m.points, m.normals
    gn = np.cross(p[tris[:, 1]] - p[tris[:, 0]], p[tris[:, 2]] - p[tris[:, 0]])
    vn = n[tris[:, 0]] + n[tris[:, 1]] + n[tris[:, 2]]
    flip = np.einsum("ij,ij->i", gn, vn) < 0.0
    out = tris.copy()
    out[flip, 1], out[flip, 2] = tris[flip, 2], tris[flip, 1]
    return out


def iso_polydata(meshes: Sequence[IsoMesh], centre: np.ndarray, shading: str = "spectrum") -> vtkPolyData:
    """One vtkPolyData of ``meshes`` in their order: points relative to ``centre`` (float32), triangles wound as
    ``_oriented_triangles``, and per-vertex attributes ``isoNormal`` (unit normal), ``isoStyle`` (color, opacity)
    and ``isoFit`` (the iso-spectrum (a, b) of translucent surfaces with ``shading="spectrum"``, else (0, 0))."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import numpy_to_vtk, vtk

    pts, tris = [], []
    cols: dict[str, list[np.ndarray]] = {k: [] for k in _ATTRIBUTES}
    base = 0
    for m in meshes:
        st = m.style
        n = len(m.points)
        fit = (0.0, 0.0)
        if shading == "spectrum" and 0.0 < float(st.opacity) < 1.0:
            f = fit_spectrum(float(st.opacity))
            fit = (f.a, f.b)
        pts.append(np.asarray(m.points, np.float64) - centre)
        tris.append(_oriented_triangles(m) + base)
        cols["isoNormal"].append(np.asarray(m.normals, np.float64).reshape(n, 3))
        cols["isoStyle"].append(np.tile([*st.color, float(st.opacity)], (n, 1)))
        cols["isoFit"].append(np.tile(fit, (n, 1)))
        base += n
    pd = vtk.vtkPolyData()
    vp = vtk.vtkPoints()
    allp = np.concatenate(pts) if pts else np.zeros((0, 3))
    vp.SetData(numpy_to_vtk(np.ascontiguousarray(allp, np.float32), deep=True))
    pd.SetPoints(vp)
    for name, parts in cols.items():
        width = {"isoNormal": 3, "isoStyle": 4, "isoFit": 2}[name]
        arr = np.concatenate(parts) if parts else np.zeros((0, width))
        va = numpy_to_vtk(np.ascontiguousarray(arr, np.float32), deep=True)
        va.SetName(name)
        pd.GetPointData().AddArray(va)
    conn = np.concatenate(tris) if tris else np.zeros((0, 3), np.int64)
    cells = vtk.vtkCellArray()
    cells.SetData(numpy_to_vtk(np.arange(0, 3 * len(conn) + 1, 3, dtype=np.int64), deep=True),
                  numpy_to_vtk(np.ascontiguousarray(conn.reshape(-1), np.int64), deep=True))
    pd.SetPolys(cells)
    return pd


class GLIsoSurfaces:
    """The isosurfaces ``meshes`` (of any number of volumes) in a PyVista plotter's renderer, drawn in ``mode`` (one
    of ``volviz.iso.composite.MODES``) with ``shading`` "spectrum" or "flat" (module docstring). ``lighting=False``
    leaves colors unlit (as composite.py's ``lighting``). ``peels``: depth-peeling layers at most in exact mode.
    ``peel_with_volumes=False``: exact mode peels over the finished scene even with a regular volume shown (the
    drawing before issue #28, for ``volviz bench iso_modes_volume``)."""

    def __init__(self, plotter: Any, meshes: Sequence[IsoMesh], mode: str = "3pass", shading: str = "spectrum",
                 lighting: bool = True, peels: int = 64, peel_with_volumes: bool = True) -> None:
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        if shading not in ("spectrum", "flat"):
            raise ValueError(f"shading must be 'spectrum' or 'flat', got {shading!r}")
        self.plotter = plotter
        self.renderer = plotter.renderer
        self.meshes = list(meshes)
        self.shading = shading
        self.ambient = AMBIENT if lighting else 1.0
        self.peels = int(peels)
        ren = self.renderer
        #: exact mode peels in the renderer with its regular volumes (module docstring); fixed for this object
        self.with_volumes = peel_with_volumes and bool(shown_regular_volumes(ren)) and ren.GetPass() is None
        self._saved = (ren.GetUseDepthPeeling(), ren.GetUseOIT(), ren.GetMaximumNumberOfPeels(),
                       ren.GetOcclusionRatio())
        pts = [m.points for m in self.meshes if len(m.points)]
        allp = np.concatenate(pts) if pts else np.zeros((1, 3))
        lo, hi = point_extent(allp)
        self.centre = 0.5 * (lo + hi)
        opaque = [m for m in self.meshes if m.style.opaque and m.n_triangles]
        clear = [m for m in self.meshes if not m.style.opaque and m.n_triangles]
        self._fbo: Any = None
        self._fbo_size: tuple[int, int] | None = None
        self._back_tex: Any = None
        self._pushed = False
        self.actors: dict[int, Any] = {}
        self._observers: list[tuple[Any, int]] = []
        if opaque:
            self._add(_OPAQUE, iso_polydata(opaque, self.centre, shading))
        self._peel_layer: PeelLayer | None = None
        self._translucent: Any = None
        if clear:
            self._translucent = iso_polydata(clear, self.centre, shading)
            for kind in (_OVER, _ATTENUATE, _BACK, _EMIT):
                self._add(kind, self._translucent)
        self._observers.append((ren, ren.AddObserver(vtk.vtkCommand.EndEvent, self._on_end)))
        self.mode = ""
        self.set_mode(mode)

    # --- set-up --------------------------------------------------------------------------------------------------
    def _add(self, kind: int, pd: Any, renderer: Any = None) -> Any:
        """An actor of ``pd`` drawing the pass ``kind``, added to ``renderer`` (default: the plotter's)."""
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import premultiplied_texture, shader_observer, vtk

        mapper = vtk.vtkOpenGLPolyDataMapper()
        mapper.SetInputData(pd)
        mapper.ScalarVisibilityOff()
        # vertexMC must be the points as given (relative to the centre already): VTK's automatic shift and per-axis
        # scale of the vertex buffer (applied to data more than ~32 units across) would bend the view rays
        mapper.SetVBOShiftScaleMethod(vtk.vtkPolyDataMapper.DISABLE_SHIFT_SCALE)
        for name in _ATTRIBUTES:
            mapper.MapDataArrayToVertexAttribute(name, name, vtk.vtkDataObject.FIELD_ASSOCIATION_POINTS, -1)
        sp = vtk.vtkShaderProperty()
        sp.SetVertexShaderCode(shader_source("iso_surface_vs.glsl"))
        sp.SetFragmentShaderCode(shader_source("iso_surface_fs.glsl"))
        actor = vtk.vtkActor()
        actor.SetMapper(mapper)
        actor.SetShaderProperty(sp)
        actor.SetPosition(*self.centre)
        if kind == _OPAQUE:
            actor.ForceOpaqueOn()
        else:
            actor.ForceTranslucentOn()
        if kind == _EMIT:
            actor.SetTexture(premultiplied_texture())   # (ONE, ONE_MINUS_SRC_ALPHA), restored by VTK
        on_update_shader = shader_observer(lambda program: self._on_update_shader(kind, program))
        self._observers.append((mapper, mapper.AddObserver(vtk.vtkCommand.UpdateShaderEvent, on_update_shader)))
        self.actors[kind] = actor
        (renderer or self.renderer).AddActor(actor)
        return actor

    # --- per draw ------------------------------------------------------------------------------------------------
    def _on_update_shader(self, kind: int, program: Any) -> None:
        """Uniforms of the pass (the actors share one program) and, for the back-face pass of 4-pass, volviz's own
        depth target bound in place of the scene's framebuffer until the emission pass."""
        if program is None:
            return
        cam = self.renderer.GetActiveCamera()
        eye = np.asarray(cam.GetPosition(), np.float64)
        fwd = np.asarray(cam.GetFocalPoint(), np.float64) - eye
        fwd /= max(float(np.linalg.norm(fwd)), 1e-300)
        program.SetUniform3f("isoEye", [float(v) for v in eye - self.centre])
        program.SetUniform3f("isoForward", [float(v) for v in fwd])
        program.SetUniformi("isoParallel", int(bool(cam.GetParallelProjection())))
        program.SetUniformi("isoPass", _OVER if kind == _PEEL else kind)
        program.SetUniformf("isoAmbient", float(self.ambient))
        program.SetUniformi("isoClipZ", int(kind == _EMIT and self.mode == "4pass"))
        state = self.renderer.GetState()
        if kind == _BACK:
            self._bind_back_target(state)
        elif kind == _EMIT and self.mode == "4pass":
            if self._pushed:
                state.PopFramebufferBindings()
                self._pushed = False
            self._back_tex.Activate()
            program.SetUniformi("isoBackDepth", self._back_tex.GetTextureUnit())

    def _bind_back_target(self, state: Any) -> None:
        """Bind (making it at the renderer's size when needed) the framebuffer with a float depth texture into which
        the back faces are drawn with depth writes on; its depth is cleared to the far plane."""
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        ren_win = self.renderer.GetRenderWindow()
        size = window_size(self.renderer)
        state.PushFramebufferBindings()
        self._pushed = True
        if self._fbo is None or self._fbo_size != size:
            self._release_target()
            fbo = vtk.vtkOpenGLFramebufferObject()
            fbo.SetContext(ren_win)
            fbo.Bind()
            color = vtk.vtkTextureObject()
            color.SetContext(ren_win)
            color.Allocate2D(size[0], size[1], 4, vtk.VTK_UNSIGNED_CHAR)
            depth = vtk.vtkTextureObject()
            depth.SetContext(ren_win)
            depth.SetMinificationFilter(vtk.vtkTextureObject.Nearest)
            depth.SetMagnificationFilter(vtk.vtkTextureObject.Nearest)
            depth.AllocateDepth(size[0], size[1], vtk.vtkTextureObject.Float32)
            fbo.AddColorAttachment(0, color)
            fbo.AddDepthAttachment(depth)
            self._fbo, self._fbo_size, self._back_tex = fbo, size, depth
        self._fbo.Bind()
        self._fbo.ActivateDrawBuffer(0)
        state.vtkglDepthMask(True)        # VTK's actor restores the mask after the draw
        state.vtkglClearDepth(1.0)        # VTK's clear value (vtkOpenGLRenderer::Clear)
        state.vtkglClear(glenum.DEPTH_BUFFER_BIT)

    def _on_end(self, *_: Any) -> None:
        state = self.renderer.GetState()
        if self._pushed:                  # the emission pass did not run: give the scene its framebuffer back
            state.PopFramebufferBindings()
            self._pushed = False
        if self._back_tex is not None:
            self._back_tex.Deactivate()

    def _release_target(self) -> None:
        ren_win = self.renderer.GetRenderWindow()
        if self._fbo is not None and ren_win is not None:
            self._fbo.ReleaseGraphicsResources(ren_win)
            self._back_tex.ReleaseGraphicsResources(ren_win)
        self._fbo = self._back_tex = self._fbo_size = None

    # --- public --------------------------------------------------------------------------------------------------
    def set_mode(self, mode: str) -> None:
        """Show the surfaces in ``mode`` (2pass, 3pass, 4pass or exact) from the next render on."""
        if mode not in MODES:
            raise ValueError(f"unknown transparency mode {mode!r}; choose from {MODES}")
        self.mode = mode
        shown = {"2pass": (_OVER,), "exact": (),        # exact: the peeling layer's own actor, made below
                 "3pass": (_ATTENUATE, _EMIT), "4pass": (_ATTENUATE, _BACK, _EMIT)}[mode]
        for kind, actor in self.actors.items():
            actor.SetVisibility(kind in (_OPAQUE, _PEEL) or kind in shown)
        ren = self.renderer
        if mode == "exact":
            peel, oit = self._saved[:2]
            ren.SetUseDepthPeeling(peel)                 # the renderer's own translucent props as before
            ren.SetUseOIT(oit)
            if _PEEL not in self.actors and self._translucent is not None:
                if self.with_volumes:                    # peeled by the renderer with its volumes
                    self._add(_PEEL, self._translucent)
                    peel_volumes(self.plotter, shown_regular_volumes(ren), True, self.peels)
                else:
                    self._peel_layer = PeelLayer(ren, self.peels)
                    self._peel_layer.add(self._add(_PEEL, self._translucent, self._peel_layer.renderer))
        else:
            ren.SetUseDepthPeeling(False)
            ren.SetUseOIT(False)
            self._remove_peel_layer()

    @property
    def peels_volumes(self) -> bool:
        """Whether the exact mode's surfaces are peeled by the renderer together with its regular volumes."""
        return _PEEL in self.actors and self._peel_layer is None

    def _remove_peel_layer(self) -> None:
        if _PEEL in self.actors:
            if self._peel_layer is not None:
                self._peel_layer.remove()
                self._peel_layer = None
            else:
                self.renderer.RemoveActor(self.actors[_PEEL])
                peel_volumes(self.plotter, [], False)
            mapper = self.actors.pop(_PEEL).GetMapper()
            for obj, tag in [o for o in self._observers if o[0] is mapper]:
                obj.RemoveObserver(tag)
                self._observers.remove((obj, tag))

    def remove(self) -> None:
        """Take the surfaces out of the renderer and restore its depth-peeling and OIT settings (call before closing
        the plotter)."""
        for obj, tag in self._observers:
            obj.RemoveObserver(tag)
        self._observers = []
        self._remove_peel_layer()
        for actor in self.actors.values():
            self.renderer.RemoveActor(actor)
        self.actors = {}
        self._release_target()
        peel, oit, n, ratio = self._saved
        ren = self.renderer
        ren.SetUseDepthPeeling(peel)
        ren.SetUseOIT(oit)
        ren.SetMaximumNumberOfPeels(n)
        ren.SetOcclusionRatio(ratio)


class GLIsoView(IsoModeView):
    """The translucent isosurfaces of a scene in one transparency mode on the GPU (``GLIsoSurfaces``), behind the calls
    the scene controller makes of the CPU ``IsoOverlay``: ``mode`` (set: the next render draws in it),
    ``set_surfaces(meshes, lod, shading)`` (the visible components' translucent surfaces; opaque ones stay the
    components' VTK actors, which the passes see in the depth buffer as the CPU overlay sees them in the read-back
    depth), ``update`` (the statistics; VTK draws the passes at every render, there is no image to re-make),
    ``remove`` and ``stats``.

    The surfaces are drawn at full resolution: the LOD chains (``lod``) set the CPU rasteriser's work per camera and
    are not used here (as VTK's own "vtk" mode draws the full surfaces). The window is held single-sample while the
    view exists (the back-face target of 4-pass and the CPU compositor it is measured against have one sample per
    pixel). ``stats``: ``method`` ("iso <mode> (gpu)"), ``triangles`` (translucent triangles uploaded),
    ``triangles_drawn`` (per frame: once per pass for 2/3/4-pass; None for exact, whose number of peeled layers VTK
    does not report), ``volume_s`` (the window's last frame: the passes and the rest of the scene) and ``size``."""

    kind = "iso"
    backend = "gpu"

    def __init__(self, plotter: Any, meshes: Sequence[IsoMesh] = (), mode: str = "3pass",
                 shading: str = "spectrum") -> None:
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        self.plotter = plotter
        self.meshes: list[IsoMesh] = []
        self.lod: list[Optional[tuple[LodChain, float]]] = []   # per mesh: its LOD chain, triangles per pixel²
        self.shading = shading
        self.surfaces: GLIsoSurfaces | None = None
        self.stats: dict[str, Any] = {}
        self._built = False
        self._frame_start = 0.0
        self._frame_s = 0.0
        self.mode = mode
        hold_single_sample(plotter, self)
        win = plotter.ren_win              # the window's frame: the exact mode's peeling layer draws after the renderer
        self._observers = [(win, win.AddObserver(vtk.vtkCommand.StartEvent, self._on_start)),
                           (win, win.AddObserver(vtk.vtkCommand.EndEvent, self._on_end))]
        self.set_surfaces(list(meshes), [None] * len(meshes), shading)

    def _mode_changed(self, mode: str) -> None:
        if self.surfaces is not None:
            self.surfaces.set_mode(mode)

    def set_surfaces(self, meshes: Sequence[IsoMesh], lod: Sequence[Optional[tuple[LodChain, float]]],
                     shading: str) -> None:
        """Draw ``meshes`` (translucent surfaces of any number of volumes) from the next render on; the vertex buffer
        is made again only when the meshes or the shading changed (the controller passes the same meshes after
        every visibility, clipping or mode call)."""
        meshes = list(meshes)
        ren = self.plotter.renderer
        same = (shading == self.shading and len(meshes) == len(self.meshes)
                and all(a is b for a, b in zip(meshes, self.meshes))
                and (self.surfaces is None or self.surfaces.with_volumes == (bool(shown_regular_volumes(ren))
                                                                            and ren.GetPass() is None)))
        self.meshes, self.lod, self.shading = meshes, list(lod), shading
        if same and self._built:
            return
        self._built = True
        if self.surfaces is not None:
            self.surfaces.remove()
            self.surfaces = None
        if any(m.n_triangles for m in self.meshes):
            self.surfaces = GLIsoSurfaces(self.plotter, self.meshes, self.mode, shading)

    @property
    def peels_volumes(self) -> bool:
        """Whether the surfaces are peeled by the renderer with its regular volumes (exact mode with a regular volume
        shown: ``GLIsoSurfaces.peels_volumes``); the scene controller keeps the peeling on meanwhile."""
        return self.surfaces is not None and self.surfaces.peels_volumes

    def _on_start(self, *_: Any) -> None:
        self._frame_start = time.perf_counter()

    def _on_end(self, *_: Any) -> None:
        self._frame_s = time.perf_counter() - self._frame_start

    def update(self) -> dict[str, object]:
        """The statistics of the last render (nothing to re-make: VTK draws the passes at every render)."""
        n = sum(m.n_triangles for m in self.meshes)
        passes = {"2pass": 1, "3pass": 2, "4pass": 3}.get(self.mode)
        self.stats = {"method": f"iso {self.mode} (gpu)", "triangles": n,
                      "triangles_drawn": None if passes is None else passes * n, "volume_s": self._frame_s,
                      "size": window_size(self.plotter.renderer)}
        return self.stats

    def begin(self, scale: int = 1) -> None:
        """The view calls (``volviz.render.views.View``): nothing to make off the GUI thread, VTK draws the passes."""
        return None

    def compute(self, request: None, progress: ProgressCallback | None = None) -> tuple[()]:
        return ()

    def finish(self, request: None) -> dict[str, object]:
        return self.update()

    def remove(self) -> None:
        """Take the surfaces out of the renderer (its depth-peeling and OIT settings restored) and give the window
        its multisampling back."""
        for obj, tag in self._observers:
            obj.RemoveObserver(tag)
        self._observers = []
        if self.surfaces is not None:
            self.surfaces.remove()
            self.surfaces = None
        self._built = False
        release_single_sample(self.plotter, self)
