"""Pre-integrated projected tetrahedra drawn by VTK's OpenGL pipeline with volviz's own shaders (Roettger Ch. 8-9,
digest §6-7: cell projection in visibility order with a pre-integration table lookup per fragment).

    vol = GLPTVolume(plotter, mesh, tf)          # a TetMesh and a TransferFunction
    plotter.show() / plotter.screenshot()          # every render sorts for the camera of that render
    vol.set_tf(tf2)                                # replaces only the table texture

The mesh is uploaded once and per render only the back-to-front cell order (a texture of cell ids); each back face's
fragment integrates its cell's ray segment by a table lookup (3D §8.4, separable §9.1) or exactly (isosurfaces
§8.8-8.13, pre-classified §8.14), and the cells are composited "over" into a float32 target that a resolve quad
blends over the scene. How a frame is drawn (upload, order, fragment, compositing, opaque depth, multisampling,
the reduced target while the camera moves, clipping): docs/gl-passes.md "gl_pt: pre-integrated projected tetrahedra
(Roettger Ch. 8-9)"; the VTK/OpenGL facts it relies on: docs/design.md "VTK's OpenGL: what the GPU passes rely on";
errors and timings: docs/bench/gl-passes.md "gl_pt", ``docs/bench/pt-gl/``.

Not handled: a renderer that does not fill its window; depth peeling for other translucent props of the same
renderer (drawn in order). Call ``remove()`` before closing the plotter.
"""
from __future__ import annotations

import time
from typing import TYPE_CHECKING, Any, Optional, Sequence

import numpy as np

from volviz.model.datasets import TetMesh
from volviz.model.extent import point_extent
from volviz.render.gl import ScenePass, resolve_polydata, set_ray_uniforms, shader_source, texel_array, with_defines
from volviz.render.gl_pt_mesh import cell_texels, tet_polydata, texels_per_cell
from volviz.jobs import ProgressCallback
from volviz.render.gl_pt_order import CellOrder, OrderRequest
from volviz.render.gl_pt_tables import KINDS, pt_shader, resolve_shader, set_table_uniforms, upload_table
from volviz.render.gl_pt_targets import PTTargets
from volviz.render.image_overlay import hold_single_sample, release_single_sample, window_size
from volviz.render.pt_view import PTView
from volviz.render.reduced_fill import INTERACTIVE_PIXELS, reduced_size, scaled_rays
from volviz.unstructured.index_buffer import IndexBuffer, fill_cells, load_kernels
from volviz.unstructured.iso import iso_visible
from volviz.unstructured.render import Preclassified, auto_lookup, table_for, table_size
from volviz.unstructured.topology import topology, visible_cells

if TYPE_CHECKING:   # type-only: the session's clipping model, the sort's result
    from volviz.model.clip import ClipSettings
    from volviz.unstructured.sort import SortResult

__all__ = ["GLPTVolume"]

_MAX_CLIP = 8                          # clipping planes the fragment shader takes
_LOOKUPS = ("auto", "3d", "separable")
_ORDER_TEXTURE_CELLS = 2 ** 24         # cell ids a float32 order texture holds exactly
_STILL_RATE_MAX = 1.0                  # frames/s: a window's desired update rate above it is an interaction's


class GLPTVolume(CellOrder, PTView):
    """A TetMesh drawn by the GPU pre-integrated PT pass in a PyVista plotter's renderer (module docstring).

    ``lookup``: "3d" (default; n_s x n_s x n_l trilinear, ``table_size``), "separable" (degree ``degree``) or
    "auto" (as the CPU ``pt``). ``iso`` (an ``IsoTable``), ``iso_shading`` ("flat" or "smooth") and
    ``classification`` ("post" or "pre") as the CPU ``render(..., iso_mode="exact")``: exact per-segment
    isosurfaces instead of the volume (``tf`` is then ignored and may be None), or pre-classified segments integrated
    in closed form. ``sort``/``nonconvex``: as ``visibility_order``. ``stats`` holds the last new index
    buffer's CPU-side seconds (``sort_s``, ``order_s``), the number of cells drawn, and whether a new order was made
    for the camera (``sorted``: here or by ``prefetch``), taken from ``prefetch`` or reused. The order, its
    prefetching, ``reuse_order`` and the view calls ``begin`` / ``compute`` / ``finish`` (the order made on a worker
    while the GPU draws; the bench states what a reused order costs): ``volviz.render.gl_pt_order.CellOrder``.
    ``camera``: the camera of the last draw. ``set_interactive`` /
    ``interactive_pixels``: the reduced-resolution frames while the camera moves (module docstring); ``drawn_size``:
    the size the last frame's cells were drawn at. The GPU side of the PT view interface
    ``volviz.render.pt_view.PTView``: VTK draws it at every render, so ``update`` has nothing to do.
    ``keep_multisampling``: leave the window's multisampling on (module docstring; default off while the volume is
    shown). ``order_texture``: the order as a texture of cell ids over a static index buffer (None, the default:
    below 2^24 cells) or as VTK's index buffer (False); ``gpu_bytes`` states what the mesh takes on the GPU."""

    backend = "gpu"
    job = ("pt-order", "visibility order")   # the app's key for its updates, and what its worker makes

    def __init__(self, plotter: Any, mesh: TetMesh, tf: Any, *, lookup: str = "3d", n_s: int | None = None,
                 n_l: int = 64, degree: int | None = None, sort: str = "mpvo", nonconvex: str = "auto",
                 iso: Any = None, iso_shading: str = "flat", classification: str = "post",
                 keep_multisampling: bool = False, order_texture: bool | None = None) -> None:
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import numpy_to_vtk, premultiplied_texture, shader_observer, vtk

        if not isinstance(mesh, TetMesh):
            raise TypeError(f"GLPTVolume needs a TetMesh, got {type(mesh).__name__}")
        if lookup not in _LOOKUPS:
            raise ValueError(f"unknown lookup {lookup!r}; choose one of {_LOOKUPS}")
        if classification not in ("post", "pre"):
            raise ValueError(f"classification must be 'post' or 'pre', got {classification!r}")
        if iso_shading not in ("flat", "smooth"):
            raise ValueError(f"iso_shading must be 'flat' or 'smooth', got {iso_shading!r}")
        if classification == "pre" and iso is not None:
            raise ValueError("isosurfaces are post-classified; use classification='post'")
        if iso is None and tf is None:
            raise ValueError("GLPTVolume needs a transfer function or isosurfaces")
        CellOrder.__init__(self, sort, nonconvex)
        self.iso, self.iso_shading, self.classification = iso, iso_shading, classification
        smooth = iso is not None and iso_shading == "smooth"
        self.plotter = plotter
        self.renderer = plotter.renderer
        self.mesh = self.whole_mesh = mesh           # clipping cuts per fragment: the mesh stays whole
        self.topo = topology(mesh)
        self.lookup, self.n_s, self.n_l, self.degree = lookup, n_s, n_l, degree
        self.stats: dict[str, Any] = {"method": "pt-gl"}
        self.camera: Any = None
        self._index_buffer: IndexBuffer | None = None   # the arrays VTK's cells share, refilled per order
        self._table: Any = None
        self._table_tex: Any = None
        self.targets = PTTargets(self.renderer)     # the cells' float target and the opaque depth's copies
        self.interactive: bool | None = None        # None: interactive while the window's update rate says so
        self.interactive_pixels = INTERACTIVE_PIXELS
        self.drawn_size: tuple[int, int] | None = None  # the last frame's cells were drawn at this size
        self._upsample = False                      # the resolve's shader variant (``resolve_shader``)
        self._drawn = False                         # the cells were drawn this frame
        self._table_dirty = True
        self._clip = np.zeros((0, 4))
        self.tf = tf
        self._vis = self._visible()
        self.order_texture = self.topo.n_tets < _ORDER_TEXTURE_CELLS if order_texture is None else order_texture
        if self.order_texture and self.topo.n_tets >= _ORDER_TEXTURE_CELLS:
            raise ValueError(f"an order texture holds cell ids below {_ORDER_TEXTURE_CELLS}, "
                             f"the mesh has {self.topo.n_tets} cells")
        self._order_cells = np.empty(self.topo.n_tets if self.order_texture else 0, np.float32)
        self._order_count = 0
        self._order_tex: Any = None                 # the order texture (uploaded as the program is bound)
        self._order_dirty = False
        self._cells_tex: Any = None                 # the cells' corners and data as texels (uploaded once)
        self._texels: np.ndarray | None = None      # those texels made by ``compute`` on a worker, for that upload
        self._wanted = True                         # ``visible`` as asked for
        self._held = False                          # not drawn until the first ``finish`` (``hold_until_finished``)

        self.polydata = tet_polydata(mesh, smooth, attributes=not self.order_texture)
        if self.order_texture:                       # the static index buffer: slot s draws vertices 4 s .. 4 s + 3
            n = self.topo.n_tets
            offsets, conn, _ = IndexBuffer(n).fill(np.arange(n, dtype=np.int32), np.ones(n, bool))
            self.polydata.GetPolys().SetData(numpy_to_vtk(offsets, deep=True), numpy_to_vtk(conn, deep=True))
        self.mapper = vtk.vtkOpenGLPolyDataMapper()
        self.mapper.SetInputData(self.polydata)
        self.mapper.ScalarVisibilityOff()
        sp = vtk.vtkShaderProperty()
        vertex_shader = pt_shader("pt_tet_vs.glsl", smooth)
        if self.order_texture:
            vertex_shader = with_defines(vertex_shader, "#define PT_ORDER_TEXTURE\n"
                                                        f"#define PT_TEXELS {texels_per_cell(smooth)}\n")
        sp.SetVertexShaderCode(vertex_shader)
        self._kind: tuple[int, int] = (-1, -1)   # the fragment shader's (PT_KIND, PT_CLIPS)
        attributes = self.polydata.GetPointData()
        for name in (attributes.GetArrayName(i) for i in range(attributes.GetNumberOfArrays())):
            self.mapper.MapDataArrayToVertexAttribute(name, name, vtk.vtkDataObject.FIELD_ASSOCIATION_POINTS, -1)
        self.actor = vtk.vtkActor()
        self.actor.SetMapper(self.mapper)
        self.actor.SetShaderProperty(sp)
        self._apply_kind()
        self.actor.SetPosition(*self.topo.origin)
        self.actor.ForceTranslucentOn()
        self.actor.GetProperty().FrontfaceCullingOn()
        self.actor.SetTexture(premultiplied_texture())
        self.resolve_mapper = vtk.vtkOpenGLPolyDataMapper()
        self.resolve_mapper.ScalarVisibilityOff()
        pts = self.topo.points
        self.resolve_mapper.SetInputData(resolve_polydata(np.stack(point_extent(pts), axis=1)))
        rsp = vtk.vtkShaderProperty()
        rsp.SetVertexShaderCode(shader_source("pt_resolve_vs.glsl"))
        rsp.SetFragmentShaderCode(resolve_shader(False))
        self.resolve_actor = vtk.vtkActor()
        self.resolve_actor.SetMapper(self.resolve_mapper)
        self.resolve_actor.SetShaderProperty(rsp)
        self.resolve_actor.SetPosition(*self.topo.origin)
        self.resolve_actor.ForceTranslucentOn()
        self.resolve_actor.SetTexture(premultiplied_texture())

        self.renderer.SetUseDepthPeeling(False)    # translucent props drawn in order: the cells, then the resolve
        self.renderer.SetUseOIT(False)
        self.keep_multisampling = keep_multisampling
        self.scene_pass: ScenePass | None = None
        if not keep_multisampling:
            hold_single_sample(plotter, self)      # one color per pixel, as the CPU backend's overlays
            # the renderer's float32 scene target, shared with the GL fog layers; the volume itself draws into its
            # own target (module docstring) and works with or without it
            self.scene_pass = ScenePass.acquire(self.renderer, self)
        self._observers = [         # as each mapper's program is bound: the cells' or the resolve's set-up
            (self.mapper, self.mapper.AddObserver(vtk.vtkCommand.UpdateShaderEvent,
                                                  shader_observer(self._on_update_shader))),
            (self.resolve_mapper, self.resolve_mapper.AddObserver(vtk.vtkCommand.UpdateShaderEvent,
                                                                  shader_observer(self._on_resolve))),
            (self.renderer, self.renderer.AddObserver(vtk.vtkCommand.StartEvent, self._on_start)),
            (self.renderer, self.renderer.AddObserver(vtk.vtkCommand.EndEvent, self._on_end)),
        ]
        self.renderer.AddActor(self.actor)
        self.renderer.AddActor(self.resolve_actor)

    # --- per frame -----------------------------------------------------------------------------------------------
    def _on_start(self, *_: Any) -> None:
        """Before each render: the shader variants for this frame and the cells' order for its camera
        (``CellOrder._order_frame``)."""
        if not self.actor.GetVisibility():
            return
        self._apply_kind()
        size = window_size(self.renderer)
        self.drawn_size = self.draw_size()
        self._apply_upsample(self.drawn_size != size)
        self.camera = self._camera()
        self._order_frame(self.camera, size)

    def _set_index_buffer(self, order: np.ndarray, visible: np.ndarray) -> np.ndarray:
        """Draw the cells of ``order`` with ``visible[cell]`` back to front (4 triangles each) from the next render
        on; returns them. The cull and the 32-bit triangles are one Numba pass into arrays kept between frames
        (``volviz.unstructured.index_buffer``) and shared with VTK, which builds and uploads the index buffer from
        them; they are refilled only here, between renders."""
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import numpy_to_vtk

        if self.order_texture:                       # the order texture's cells, uploaded as the program is bound
            self._order_count = fill_cells(order, visible, self._order_cells)
            self._order_dirty = True
            return self._order_cells[:self._order_count].astype(np.int32)
        if self._index_buffer is None:
            self._index_buffer = IndexBuffer(self.topo.n_tets)   # refuses meshes beyond 32-bit vertex indices
        offsets, conn, cells = self._index_buffer.fill(order, visible)
        self.polydata.GetPolys().SetData(numpy_to_vtk(offsets, deep=False), numpy_to_vtk(conn, deep=False))
        self.polydata.Modified()
        return cells.copy()     # the buffer's cells are overwritten by the next order

    def _on_end(self, *_: Any) -> None:
        self.targets.restore()                     # only if the resolve did not draw
        self._drawn = False
        for tex in (self._table_tex, self._order_tex, self._cells_tex):
            if tex is not None:
                tex.Deactivate()
        self.targets.deactivate()

    def _on_resolve(self, program: Any) -> None:
        """The resolve's draw: back to the scene's framebuffer; the volume's image goes over it."""
        self.targets.restore()
        color = self.targets.color
        if color is not None:
            color.Activate()
            program.SetUniformi("ptAccum", color.GetTextureUnit())
        program.SetUniformi("ptDrawn", int(self._drawn and color is not None))
        if self._upsample:
            program.SetUniform2f("ptViewSize", [float(v) for v in window_size(self.renderer)])

    def _visible(self) -> np.ndarray:
        """The cells drawn: those with some opacity under the TF (Roettger §9.1), or that an isovalue crosses."""
        if self.iso is not None:
            return iso_visible(self.mesh, self.iso)
        return visible_cells(self.mesh, self.tf.scalars, self.tf.extinction)

    def _resolved_lookup(self) -> tuple[str, int | None]:
        """(lookup, degree) with "auto" decided as the CPU ``pt`` does, by the TF's largest optical depth per cell."""
        if self.lookup != "auto":
            return self.lookup, self.degree
        lookup, auto_degree = auto_lookup(self.tf.max_extinction * max(self.topo.max_edge, 1e-12))
        return lookup, self.degree or auto_degree

    def _apply_kind(self) -> None:
        """The fragment shader made for this volume's segment evaluation and number of clipping planes (recompiled by
        VTK when either changes, e.g. an "auto" lookup switching tables with the TF, or a new clipping plane)."""
        kind = KINDS["iso" if self.iso is not None else "pre" if self.classification == "pre" else
                     self._resolved_lookup()[0]]
        if (kind, len(self._clip)) != self._kind:
            self._kind = (kind, len(self._clip))
            self.actor.GetShaderProperty().SetFragmentShaderCode(
                pt_shader("pt_tet_fs.glsl", self.iso is not None and self.iso_shading == "smooth", *self._kind))

    def _build_table(self) -> Any:
        if self.iso is not None:
            return self.iso
        if self.classification == "pre":
            return Preclassified(self.tf)
        tf, topo = self.tf, self.topo
        l_max = max(topo.max_edge, 1e-12)
        lookup, degree = self._resolved_lookup()
        if lookup == "3d":
            return table_for(self.mesh, tf, "3d", table_size(tf.max_extinction * l_max, self.n_s or 128, self.n_l),
                             l_max)
        return table_for(self.mesh, tf, "separable", (self.n_s or 256, int(degree or 2)), l_max)

    def _on_update_shader(self, program: Any) -> None:
        """Uniforms and textures for the draw (set as the mapper's program is bound)."""
        if program is None:
            return
        ren_win = self.renderer.GetRenderWindow()
        if self._table is None or self._table_dirty:
            self._table = self._build_table()
            if self._table_tex is not None:
                self._table_tex.ReleaseGraphicsResources(ren_win)
            self._table_tex = upload_table(ren_win, self._table)
            self._table_dirty = False
        cam = self._camera()
        size = window_size(self.renderer)
        drawn = self.drawn_size or size
        rb = cam.rays(size, origin=self.topo.origin)
        if drawn != size:                          # an interactive frame: the same view's rays at fewer pixels
            rb = scaled_rays(rb, size, drawn)
        set_ray_uniforms(program, rb, drawn[1], cam.clipping_range, cam.parallel)
        if len(self._clip):
            program.SetUniform4fv("clipPlanes", len(self._clip), [float(x) for x in self._clip.ravel()])
        depth = self.targets.bind(size, drawn)     # the opaque scene's depth, the volume's own color target
        depth.Activate()
        self._drawn = True
        program.SetUniformi("useDepth", 1)
        program.SetUniformi("opaqueDepth", depth.GetTextureUnit())
        self._table_tex.Activate()
        program.SetUniformi("ptTable", self._table_tex.GetTextureUnit())
        if self.order_texture:
            self._bind_order(program, ren_win)
        set_table_uniforms(program, self._table, self.iso_shading == "smooth", cam.frame()[2])

    def _bind_order(self, program: Any, ren_win: Any) -> None:
        """The order texture's uniforms (``PT_ORDER_TEXTURE``): the cells' texels (uploaded at the first draw) and the
        order, uploaded when a new one was set since the last draw (0.75 MB for the Blunt Fin: the only per-camera
        upload; VTK's index buffer stays)."""
        if self._cells_tex is None:
            texels, self._texels = self._texels, None
            if texels is None:
                texels = cell_texels(self.mesh, self._smooth_cells())
            self._cells_tex = texel_array(ren_win, texels, "cells'")
        if self._order_dirty or self._order_tex is None:
            start = time.perf_counter()
            self._order_tex = texel_array(ren_win, self._order_cells[:, None], "cell order", into=self._order_tex)
            self.stats["upload_s"] = time.perf_counter() - start     # the call's CPU side (the bench reports it)
            self._order_dirty = False
        for name, tex in (("ptCells", self._cells_tex), ("ptOrder", self._order_tex)):
            tex.Activate()
            program.SetUniformi(name, tex.GetTextureUnit())
            program.SetUniformi(name + "Width", int(tex.GetWidth()))
        program.SetUniformi("ptCount", int(self._order_count))

    def _apply_upsample(self, on: bool) -> None:
        """The resolve's shader variant for this frame (VTK keeps both programs compiled once made)."""
        if on != self._upsample:
            self._upsample = on
            self.resolve_actor.GetShaderProperty().SetFragmentShaderCode(resolve_shader(on))

    # --- public --------------------------------------------------------------------------------------------------
    def gpu_bytes(self) -> int:
        """The bytes of the mesh's data on the GPU: the vertex buffer (float32 corners, and without the order texture
        the cell data repeated at each), the index buffer (4 triangles of 32-bit indices per cell) and, with the order
        texture, the cells' texels and the order (the table and the targets do not grow with the mesh)."""
        data = self.polydata.GetPointData()
        vertex = self.polydata.GetNumberOfPoints() * 12 + sum(
            4 * data.GetArray(i).GetNumberOfValues() for i in range(data.GetNumberOfArrays()))
        n = self.topo.n_tets
        texels = n * (16 * texels_per_cell(self.iso is not None and self.iso_shading == "smooth") + 4)
        return int(vertex + 48 * n + (texels if self.order_texture else 0))

    def set_interactive(self, on: bool | None) -> None:
        """Draw at reduced resolution from the next render on (True: the camera is moving; at most
        ``interactive_pixels`` pixels, upsampled), at full resolution (False), or follow the render window (None,
        the default: interactive while its desired update rate exceeds 1 frame/s, as VTK's interactor styles set it
        for a drag and back to the still rate when the drag ends)."""
        self.interactive = on

    def is_interactive(self) -> bool:
        """Whether the next render is an interactive one (``set_interactive``)."""
        if self.interactive is not None:
            return bool(self.interactive)
        ren_win = self.renderer.GetRenderWindow()
        return ren_win is not None and ren_win.GetDesiredUpdateRate() > _STILL_RATE_MAX

    def draw_size(self) -> tuple[int, int]:
        """The size the next render draws the cells at: the renderer's, or during an interaction the reduced one
        (``volviz.render.reduced_fill.reduced_size``)."""
        size = window_size(self.renderer)
        return reduced_size(size, self.interactive_pixels) if self.is_interactive() else size

    @property
    def target_size(self) -> tuple[int, int] | None:
        """The size of the float target the cells were last drawn into (None before the first draw)."""
        return self.targets.size

    def _use_tf(self, tf: Any) -> None:
        """A new transfer function (``set_tf``): the table texture is rebuilt at the next render and the
        zero-opacity culling follows it (a new index buffer from the same visibility order: the sort does not depend
        on the TF; the vertex buffer stays)."""
        self.tf = tf
        self._vis = self._visible()
        self._table_dirty = True
        self._recull = True

    def set_clip_planes(self, planes: Sequence[tuple[Sequence[float], Sequence[float]]] = (),
                        box: Sequence[float] | None = None) -> None:
        """Clip the volume per fragment (the exact ray segment is cut, not the cells): ``planes`` is a sequence of
        (normal, origin), each keeping the half-space its normal points into (VTK's convention for a mapper's
        clipping planes); ``box`` (xmin, xmax, ymin, ymax, zmin, zmax) crops to an axis-aligned box. At most 8 in
        all; no arguments removes them."""
        rows = []
        for normal, origin in planes:
            n = np.asarray(normal, np.float64).reshape(3)
            n = n / np.linalg.norm(n)
            rows.append(np.append(-n, -n @ (np.asarray(origin, np.float64).reshape(3) - self.topo.origin)))
        if box is not None:
            b = np.asarray(box, np.float64).reshape(3, 2) - self.topo.origin[:, None]
            for axis in range(3):
                e = np.eye(3)[axis]
                rows += [np.append(-e, -b[axis, 0]), np.append(e, b[axis, 1])]
        if len(rows) > _MAX_CLIP:
            raise ValueError(f"at most {_MAX_CLIP} clipping planes, got {len(rows)}")
        self._clip = np.array(rows, np.float64).reshape(-1, 4)

    def set_clip(self, clip: ClipSettings) -> bool:
        """Clip by ``volviz.model.clip.ClipSettings`` (its planes and box) per fragment (``set_clip_planes``); returns
        True (``PTView.set_clip``: nothing for the caller to cut)."""
        self.set_clip_planes([(p.normal, p.point) for p in clip.all_planes()])
        return True

    def update(self) -> None:
        """Nothing to re-make: the next render sorts for its camera and draws (``PTView.update``), a volume held
        until its first ``finish`` too (the views made here, not on a worker)."""
        self._release()

    def compute(self, request: OrderRequest, progress: Optional[ProgressCallback] = None
                ) -> tuple[Optional[SortResult]]:
        """Any thread: the order (``CellOrder.compute``) and, before the first draw, the arrays the first bind of the
        cells' program would make on the GUI thread: the cells' texels (``cell_texels``, handed to the upload) and
        the pre-integration table (``table_for``'s cache, which the bind then finds for this TF); the index buffer's
        kernels are loaded for the order's types (``load_kernels``)."""
        if self.order_texture and self._cells_tex is None and self._texels is None:
            self._texels = cell_texels(self.mesh, self._smooth_cells())
        if self._table is None:
            self._build_table()
        result = super().compute(request, progress)
        if result[0] is not None:
            load_kernels(result[0].order, self._vis)
        return result

    def finish(self, request: OrderRequest, result: Optional[SortResult]) -> None:
        """GUI thread: ``CellOrder.finish``; a volume held until now is drawn from the next render on."""
        super().finish(request, result)
        self._release()

    def hold_until_finished(self) -> None:
        """Draw nothing until the first ``finish``: a caller that makes the views on a worker (the app) then has the
        first draw's arrays made there too (``compute``), not in a render of the GUI thread."""
        self._held = True
        self._show()

    def _release(self) -> None:
        if self._held:
            self._held = False
            self._show()

    def _smooth_cells(self) -> bool:
        return self.iso is not None and self.iso_shading == "smooth"

    def _show(self) -> None:
        on = self._wanted and not self._held
        self.actor.SetVisibility(on)
        self.resolve_actor.SetVisibility(on)

    @property
    def visible(self) -> bool:
        return self._wanted

    @visible.setter
    def visible(self, on: bool) -> None:
        self._wanted = bool(on)
        self._show()

    def remove(self) -> None:
        """Take the volume out of the renderer; the last GL pass of a renderer removes the float scene target (call
        it before closing the plotter: VTK complains when a framebuffer pass outlives its context's resources)."""
        self._close_sorter()
        for obj, tag in self._observers:
            obj.RemoveObserver(tag)
        self._observers = []
        self.renderer.RemoveActor(self.actor)
        self.renderer.RemoveActor(self.resolve_actor)
        ren_win = self.renderer.GetRenderWindow()
        for tex in (self._table_tex, self._order_tex, self._cells_tex):
            if tex is not None and ren_win is not None:
                tex.ReleaseGraphicsResources(ren_win)
        self._table_tex = self._order_tex = self._cells_tex = None
        self.targets.release()
        if not self.keep_multisampling:
            release_single_sample(self.plotter, self)
        if self.scene_pass is not None:
            self.scene_pass.release(self)
            self.scene_pass = None
