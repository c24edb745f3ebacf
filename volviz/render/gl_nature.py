"""The natural scene on the GPU backend: terrain C-LOD, sky dome, ground fog / cloud layers and C-LOD clouds all
drawn by VTK's OpenGL pipeline into the scene's own depth buffer (Roettger Ch. 10-11, digest §8-9); the GPU side of
``volviz.render.nature_view.NatureView``, whose calls it keeps (``update``, ``begin`` / ``compute`` / ``finish``,
``remove``, ``last_stats``, ``scene`` for the bounds), so the controller and the app only choose the class
(``volviz.render.backend``, view kind "nature").

- Terrain with geomorphing and the sky dome: ``NatureView``'s VTK meshes, unchanged (this class is its subclass).
- Prism layers (ground fog, cloud layers between two height fields; §10.3-10.4): one ``volviz.render.gl_fog.
  GLFogLayer`` each, on the frame's C-LOD terrain triangles and morphed layer heights (``GLFogLayer.set_geometry``
  every frame: the prisms follow the terrain's LOD as on the CPU), reading the opaque depth of the terrain and sky.
- Clouds (§11.3-11.6): the frame's C-LOD leaves in their back-to-front order, one point each; the GPU morphs them
  (``cloud_leaf_vs.glsl``: the weights of Eq. 11.6 from the eye and the corrected Eq. 11.8 along each leaf's
  ancestors, from the grid's fields and the octree's refinement thresholds uploaded once) and a geometry shader
  makes each leaf's 5 tetrahedra (split and ordered back to front as ``CloudFrame.to_tetmesh`` does), drawn by
  ``CloudPTVolume``, a ``volviz.render.gl_pt.GLPTVolume`` whose fragments
  scale the segment length by the second field as the CPU clouds do (Eq. 11.9, l' = l m̄ with m the modulating field
  over its maximum at the middle of the segment; NPR §11.6.2: the table is indexed by f, γ modulates), looked up in
  the scene's own cloud table (the CPU's, 64 x 64 x 128 over the root cube's diagonal).
- The layers are composited in ``NatureScene.volume_order`` (farthest layer first), the CPU's order: their actors
  are re-added to the renderer in that order when it changes.

``compute`` (any thread) does the LOD work and builds the vertex buffers as NumPy arrays, in two threads (the
Numba kernels release the GIL), each with half the caller's Numba threads (``volviz.numba_threads``): the terrain's
C-LOD mesh and each layer's per-point heights and emissions (``gl_fog.prism_buffers``; the prisms are made by a
geometry shader) on one, the clouds' refinement and leaf list (no morph: the GPU's) on the other; ``finish`` (GUI
thread) only hands them to VTK, sharing the arrays (``vtk_facade.shared_polydata``), and VTK uploads them and draws
everything at the next render, at the window's full size (a preview ``scale`` is ignored). No image is made on the
CPU.

Per frame the clouds upload only what their LOD mesh gained (``volviz.render.cloud_slots``): the texels of the
leaves new to it (16 bytes each: their octree address, into the next free slots, one region) and the draw order
(4 bytes per leaf), ``stats["cloud_upload_bytes"]``; every few frames a compaction re-sends the whole slot array.
A leaf that stays keeps its texel while it morphs: its corner values are made on the GPU for each eye (a
geomorphed leaf's values move with every step of the eye, so values made on the CPU would change for most leaves
every frame).

What ``GLPTVolume`` lacks for the clouds (``CloudPTVolume`` works around it through its private members, listed
there): a per-cell length modulation attribute, a caller-given back-to-front order (the leaves' BSP order; MPVO would
sample the non-conforming leaf mesh's boundaries), a caller-given table (its own is built per mesh over the mesh's
longest edge), cells made on the GPU, and a public way to replace the mesh by a frame's buffers.

Errors against the CPU ``NatureView`` of the same camera and LOD (8-bit screen units), measured on llvmpipe in
``tests/test_render_gl_nature.py``: see the bounds there.
"""
from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor, wait
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Callable, Optional, Union

import numpy as np

from volviz.model.datasets import TetMesh
from volviz.nature.clouds import CloudFrame, CloudLOD, CloudShading, CloudVolume
from volviz.nature.nature_scene import NatureScene
from volviz.numba_threads import numba_threads, share
from volviz.render.cloud_slots import RESERVED, LeafSlots, leaf_keys
from volviz.render.gl import release, resolve_polydata, shader_source, texel_array
from volviz.render.gl_fog import GLFogLayer, PrismBuffers, prism_buffers
from volviz.render.gl_pt import GLPTVolume
from volviz.render.image_overlay import hold_single_sample, release_single_sample
from volviz.render.nature_view import NatureRequest, NatureSceneView, NatureView
from volviz.unstructured.topology import visible_intervals

if TYPE_CHECKING:   # type-only imports for the signatures
    from volviz.jobs import ProgressCallback
    from volviz.model.camera import Camera
    from volviz.nature.terrain import TerrainMesh

__all__ = ["CloudLeaves", "CloudPTVolume", "EitherNatureView", "GLNatureFrame", "GLNatureView", "PrismGeometry",
           "cloud_field_texels", "cloud_leaves", "modulation_scale"]

# (anchor in gl_pt's fragment shader, text added after it): the modulation's flat varying, and the length scaled by
# the modulating field at the middle of the clipped segment
_FS_PATCH = (("flat in vec4 cellRange;", "\nflat in vec4 cellModulate;"),
             ("float len = (t1 - t0) * length(d);",
              "\n  len *= max(dot(cellModulate.xyz, o + 0.5 * (t0 + t1) * d) + cellModulate.w, 0.0);"))

#: the most intervals of the table field with extinction the geometry shader tests a leaf against (``cloudVisible``)
_VISIBLE_INTERVALS = 8
#: the most octree levels the vertex shader's morph walks (``cloudOffsets``)
_MAX_LEVELS = 16


def _patched(name: str, patches: tuple[tuple[str, str], ...]) -> str:
    text = shader_source(name)
    for anchor, added in patches:
        if text.count(anchor) != 1:
            raise RuntimeError(f"gl_pt's {name} changed: the clouds' modulation needs the line {anchor!r} once")
        text = text.replace(anchor, anchor + added)
    return text


def modulation_scale(volume: CloudVolume, shading: CloudShading) -> float:
    """The modulating field's maximum (the CPU's ``m_scale``): γ_max for NPR (table field f), f_max otherwise."""
    return max(float(volume.gamma.max() if shading.table_field == "f" else volume.f.max()), 1e-12)


def cloud_field_texels(volume: CloudVolume, shading: CloudShading) -> np.ndarray:
    """Per grid point (C order of the (nx, ny, nz) grid) the table field and the modulating field over its maximum
    (``modulation_scale``), (n, 2) float32: what ``cloud_leaf_vs.glsl`` morphs the leaves' corners from."""
    table, other = (volume.f, volume.gamma) if shading.table_field == "f" else (volume.gamma, volume.f)
    out = np.empty((table.size, 2), np.float32)
    out[:, 0] = table.reshape(-1)
    out[:, 1] = other.reshape(-1).astype(np.float64) / modulation_scale(volume, shading)
    return out


@dataclass
class CloudLeaves:
    """A frame's cloud leaves for ``CloudPTVolume`` (``cloud_leaves``, any thread): ``leaves`` (n, 4) int64 (level,
    a, b, c) in back-to-front order and their ``keys`` (``cloud_slots.leaf_keys``); ``bounds`` (3, 2) the volume's
    box relative to ``centre`` (the volume's); ``origin`` (relative to the centre) and ``spacing``: the grid's."""

    leaves: np.ndarray
    keys: np.ndarray
    centre: np.ndarray
    bounds: np.ndarray
    origin: np.ndarray
    spacing: np.ndarray

    @property
    def n_leaves(self) -> int:
        return int(len(self.leaves))


def cloud_leaves(frame: CloudFrame) -> CloudLeaves:
    """Any thread: a frame's leaves (``CloudLOD.update(..., morph=False)``: the GPU morphs them) with their keys."""
    lod = frame.lod
    vol = lod.volume
    origin = np.asarray(vol.origin, np.float64)
    spacing = np.asarray(vol.spacing, np.float64)
    half = 0.5 * (np.asarray(vol.shape, np.float64) - 1.0) * spacing
    centre = origin + half
    leaves = np.ascontiguousarray(frame.leaves, np.int64)
    return CloudLeaves(leaves, leaf_keys(leaves, lod.roots), centre, np.stack([-half, half], axis=1),
                       origin - centre, spacing)


def _visible_intervals(tf: Any) -> list[tuple[float, float]]:
    """The table field's intervals where the TF has extinction (``visible_intervals``), at most
    ``_VISIBLE_INTERVALS``: past that, the neighbours nearest each other are joined (a superset: leaves in the gaps
    are drawn and add nothing)."""
    merged = visible_intervals(tf.scalars, tf.extinction)
    while len(merged) > _VISIBLE_INTERVALS:
        gap = int(np.argmin([merged[i + 1][0] - merged[i][1] for i in range(len(merged) - 1)]))
        merged[gap:gap + 2] = [(merged[gap][0], merged[gap + 1][1])]
    return merged


#: a prism layer's geometry on a frame's terrain: points (n, 3), bottom and top heights (n,), triangles (m, 3)
PrismGeometry = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]


@dataclass
class GLNatureFrame:
    """What ``GLNatureView.compute`` makes for ``finish`` besides the terrain mesh: the terrain ``mesh`` again (None
    without terrain), the clouds' leaves (None without clouds), each prism layer's geometry and vertex buffer by
    name, and the ``eye`` the layers are ordered from."""

    mesh: Optional[TerrainMesh]
    clouds: Optional[CloudLeaves]
    prisms: dict[str, tuple[PrismGeometry, PrismBuffers]]
    eye: np.ndarray


@dataclass
class _FrameGeometry:
    """What ``GLPTVolume``'s draw reads of its ``topo`` for a frame drawn in a given order: the actor's origin (the
    ray basis is taken relative to it) and the number of cells it orders (here the leaf slots)."""

    origin: np.ndarray
    n_tets: int


class CloudPTVolume(GLPTVolume):
    """C-LOD cloud leaves on the GPU PT pass (module docstring): the shading's table, the length modulated per
    fragment (Eq. 11.9), the given back-to-front order of the leaves, and ``set_frame`` for the next frame's leaves.
    The leaves live in slots of a texel array on the GPU (``volviz.render.cloud_slots``: only the leaves a frame
    adds are uploaded); one point per slot, drawn in the frame's order; the vertex shader morphs each leaf from the
    grid's fields and the octree's refinement thresholds (two textures uploaded once) for the eye, and the geometry
    shader makes its 5 tetrahedra (``cloud_leaf_vs.glsl``, ``cloud_leaf_gs.glsl``).

    Private members of ``GLPTVolume`` used (what a public API would replace): ``_build_table`` (overridden to return
    the scene's table), ``_set_index_buffer`` (overridden: one index per leaf), ``_visible`` (overridden: the
    geometry shader culls), ``_sorted`` / ``_sorted_key`` / ``_order_key`` (the given order, kept by
    ``reuse_order``), ``_vis``, ``topo`` (``_FrameGeometry``: a frame has no mesh topology), ``_on_update_shader``
    / ``_on_end`` (extended to bind the cloud textures and set the grid, octree and eye uniforms)."""

    follows_camera = False   # the leaves' order comes with each frame (``set_frame``), for every camera

    def __init__(self, plotter: Any, leaves: CloudLeaves, lod: CloudLOD, shading: CloudShading, table: Any
                 ) -> None:
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        if lod.levels > _MAX_LEVELS:
            raise ValueError(f"cloud octree of {lod.levels} levels; the GPU morph walks at most {_MAX_LEVELS}")
        self._cloud_table = table
        self.lod = lod
        self.slots = LeafSlots()
        self.last_update: Any = None           # the last frame's ``SlotUpdate``
        self._pending: list[Any] = []          # slot updates not yet on the GPU, in order
        self._fields: np.ndarray | None = cloud_field_texels(lod.volume, shading)   # until uploaded
        self._thresholds: np.ndarray | None = None
        self._thresholds_sent: np.ndarray | None = None
        self._textures: dict[str, Any] = {}    # uniform name -> vtkTextureObject (2D-emulated texel arrays)
        self._capacity = 0
        # GLPTVolume is made on one tetrahedron (its own buffer is replaced by the frame's at once)
        one = TetMesh(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
                      np.array([[0, 1, 2, 3]]), np.zeros(4))
        super().__init__(plotter, one, shading.tf, lookup="3d")
        self.mapper.RemoveAllVertexAttributeMappings()
        # the geometry shader makes positions in model coordinates: VTK must not shift and scale the vertex buffer
        self.mapper.SetVBOShiftScaleMethod(vtk.vtkPolyDataMapper.DISABLE_SHIFT_SCALE)
        sp = self.actor.GetShaderProperty()
        sp.SetVertexShaderCode(shader_source("cloud_leaf_vs.glsl"))
        sp.SetGeometryShaderCode(shader_source("cloud_leaf_gs.glsl"))
        sp.SetFragmentShaderCode(_patched("pt_tet_fs.glsl", _FS_PATCH))
        self.stats = {"method": "pt-gl clouds"}
        self.set_frame(leaves)

    def _build_table(self) -> Any:
        return self._cloud_table

    def _visible(self) -> np.ndarray:
        """Every slot: the geometry shader drops the leaves the TF hides (their morphed values are made there)."""
        return np.ones(max(self._capacity, 1), dtype=bool)

    def set_frame(self, leaves: CloudLeaves) -> None:
        """GUI thread: the next frame's leaves (back to front): their slots (the new ones' texels uploaded at the
        next render, ``last_update``), drawn in this order for every camera, with the same table."""
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import shared_polydata

        update = self.slots.place(leaves.leaves, leaves.keys)
        self._pending = [update] if update.whole else self._pending + [update]
        self._thresholds = self.lod.refinement_thresholds()
        self._grid = (np.asarray(leaves.origin, np.float64), np.asarray(leaves.spacing, np.float64))
        if update.capacity != self._capacity:
            # one point per slot; the reserved two at the box's corners give VTK the volume's bounds
            points = np.zeros((update.capacity, 3), np.float32)
            points[:RESERVED] = leaves.bounds.T
            self.polydata = shared_polydata(points, {})
            self.mapper.SetInputData(self.polydata)
            self._capacity = update.capacity
            self._vis = self._visible()
        self.topo = _FrameGeometry(np.asarray(leaves.centre, np.float64), self._capacity)
        self.actor.SetPosition(*leaves.centre)
        if self.last_update is None:
            self.resolve_mapper.SetInputData(resolve_polydata(leaves.bounds))   # VTK culls the resolve by these
        self.resolve_actor.SetPosition(*leaves.centre)
        self.last_update = update
        self.reuse_order = True
        self._sorted = update.order.astype(np.int64)
        self._sorted_key = self._order_key = None

    def _set_index_buffer(self, order: np.ndarray, visible: np.ndarray) -> np.ndarray:
        """Draw the slots of ``order`` with ``visible[slot]`` in this order from the next render on, one point each
        (32-bit indices shared with VTK, kept referenced here); returns them."""
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import numpy_to_vtk, vtk

        cells = order[visible[order]]
        conn = np.ascontiguousarray(cells, dtype=np.int32)
        offsets = np.arange(len(conn) + 1, dtype=np.int32)
        self._cell_arrays = (offsets, conn)
        verts = vtk.vtkCellArray()
        verts.SetData(numpy_to_vtk(offsets, deep=False), numpy_to_vtk(conn, deep=False))
        self.polydata.SetVerts(verts)
        self.polydata.Modified()
        return cells

    def _texture(self, name: str, texels: np.ndarray, ren_win: Any) -> None:
        """(Re)make the 2D-emulated texel array ``name`` from ``texels`` (n, components) float32."""
        release(ren_win, [self._textures.pop(name, None)])
        self._textures[name] = texel_array(ren_win, texels, f"clouds' {name}")

    def _upload(self, ren_win: Any) -> None:
        """What changed since the last render: the grid's fields (once), the refinement thresholds (when C, c or
        the cutoff changed) and the slot updates in order (a region each, or the whole array after a compaction)."""
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        if self._fields is not None:
            self._texture("cloudFields", self._fields, ren_win)
            self._fields = None
        if self._thresholds is not None and self._thresholds is not self._thresholds_sent:
            self._texture("cloudNodes", self._thresholds.reshape(-1, 1), ren_win)
            self._thresholds_sent = self._thresholds
        for update in self._pending:
            if update.whole:
                self._texture("cloudSlots", update.texels, ren_win)
            elif len(update.texels):
                if not self._textures["cloudSlots"].UpdateTextureBuffer2DRegion(
                        update.start, len(update.texels), 4, vtk.VTK_FLOAT, update.texels):
                    raise RuntimeError("OpenGL refused the clouds' slot update")
        self._pending = []

    def _on_update_shader(self, program: Any) -> None:
        """gl_pt's uniforms and textures, the cloud textures (uploaded as they changed), and the grid, octree, eye
        and TF intervals for the vertex and geometry shaders."""
        super()._on_update_shader(program)
        if program is None:
            return
        self._upload(self.renderer.GetRenderWindow())
        for name, tex in self._textures.items():
            tex.Activate()
            program.SetUniformi(name, tex.GetTextureUnit())
            program.SetUniformi(name + "Width", int(tex.GetWidth()))
        lod = self.lod
        origin, spacing = self._grid
        eye = np.asarray(self.renderer.GetActiveCamera().GetPosition(), np.float64) - self.topo.origin
        program.SetUniform3f("cloudOrigin", [float(v) for v in origin])
        program.SetUniform3f("cloudSpacing", [float(v) for v in spacing])
        program.SetUniform3f("cloudEye", [float(v) for v in eye])
        program.SetUniform1iv("cloudShape", 3, [int(v) for v in lod.volume.shape])
        program.SetUniform1iv("cloudRoots", 3, [int(v) for v in lod.roots])
        program.SetUniformi("cloudRoot", int(lod.volume.root))
        offsets = [int(v) for v in lod.off[:lod.levels]] + [0] * (_MAX_LEVELS - lod.levels)
        program.SetUniform1iv("cloudOffsets", _MAX_LEVELS, offsets)
        program.SetUniformi("cloudGeomorph", int(lod.geomorph))
        intervals = _visible_intervals(self.tf)
        flat = [v for pair in intervals for v in pair] + [0.0] * (2 * (_VISIBLE_INTERVALS - len(intervals)))
        program.SetUniform2fv("cloudVisible", _VISIBLE_INTERVALS, flat)
        program.SetUniformi("cloudVisibleCount", len(intervals))

    def _on_end(self, *args: Any) -> None:
        super()._on_end(*args)
        for tex in self._textures.values():
            tex.Deactivate()

    def remove(self) -> None:
        """GLPTVolume's ``remove`` and the cloud textures' GL resources."""
        release(self.renderer.GetRenderWindow(), self._textures.values())
        self._textures = {}
        super().remove()


class GLNatureView(NatureSceneView[GLNatureFrame]):
    """A ``NatureScene`` in a PyVista plotter, fog and clouds on the GPU (module docstring). ``layers``: the
    ``GLFogLayer`` of each prism layer by name; ``clouds``: the ``CloudPTVolume`` (None without clouds or before the
    first frame)."""

    backend = "gpu"

    def __init__(self, plotter: Any, scene: NatureScene, size: tuple[int, int] | None = None,
                 filter_texture: bool | None = None) -> None:
        super().__init__(plotter, scene, size, filter_texture)
        self.layers: dict[str, GLFogLayer] = {}
        self.clouds: CloudPTVolume | None = None
        # the terrain half of ``compute``: one thread kept for the view's life (a new thread each frame would also
        # make Numba's OpenMP start a new team of threads for it each frame)
        self._terrain_worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix="volviz-terrain-lod")
        self._single_sample = False             # held once a fog layer or the clouds draw (``finish``)

    def compute(self, request: NatureRequest, progress: Optional[ProgressCallback] = None
                ) -> tuple[Optional[TerrainMesh], GLNatureFrame, dict[str, float]]:
        """Any thread: the LOD work of a frame (no image): the terrain's C-LOD mesh (``TerrainMesh``, also in the
        frame: ``finish`` makes its VTK poly data on the GUI thread, see ``NatureView.compute``), the prisms standing on
        it with each prism layer's vertex buffer (``prism_buffers``), on a second
        thread meanwhile the clouds' refinement and leaf list (``cloud_leaves``; both parts run
        Numba kernels that release the GIL), statistics (``lod_s``: seconds spent here). Each part's kernels get
        half the caller's Numba threads; the terrain's fan emission and prism buffers get all of them once the
        clouds are done."""
        cam, size, _ = request
        t0 = time.perf_counter()
        scene = self.scene
        stats: dict[str, float] = {}
        each, whole = share(2), share(1)
        clouds_done = threading.Event()

        def threads() -> int:
            return whole if clouds_done.is_set() else each

        with numba_threads(each):
            try:
                terrain = self._terrain_worker.submit(self._terrain_part, cam, size, threads)
            except RuntimeError:                   # removed meanwhile (its worker is shut down): a one-off thread
                terrain = ThreadPoolExecutor(max_workers=1).submit(self._terrain_part, cam, size, threads)
            clouds = None
            try:
                if scene.cloud_lod is not None:
                    if progress is not None:
                        progress(0.3, "clouds")
                    assert scene.cloud_shading is not None
                    frame = scene.cloud_lod.update(cam, size, morph=False)
                    clouds = cloud_leaves(frame)
                    stats["cloud_tets"] = float(frame.n_tets)
            except BaseException:
                clouds_done.set()
                wait([terrain])                    # no terrain work left behind
                raise
            clouds_done.set()
            mesh, prisms = terrain.result()
        if mesh is not None:
            stats["terrain_triangles"] = float(mesh.n_triangles)
        stats["lod_s"] = time.perf_counter() - t0
        return mesh, GLNatureFrame(mesh, clouds, prisms, np.asarray(cam.position, np.float64)), stats

    def _terrain_part(self, cam: Camera, size: tuple[int, int], threads: Callable[[], int]
                      ) -> tuple[Optional[TerrainMesh], dict[str, tuple[PrismGeometry, PrismBuffers]]]:
        """The terrain's C-LOD mesh and each prism layer's (geometry, ``prism_buffers``), their kernels on
        ``threads()`` Numba threads (asked for when each stage starts)."""
        scene = self.scene
        with numba_threads(threads()):
            mesh = scene.terrain_mesh(cam, size, emit_threads=threads)
        if mesh is None:
            return None, {}
        with numba_threads(threads()):
            return mesh, self._prism_layers(mesh)

    def _prism_layers(self, mesh: TerrainMesh) -> dict[str, tuple[PrismGeometry, PrismBuffers]]:
        """Each prism layer's (geometry, ``prism_buffers``) on the terrain ``mesh``, by name."""
        scene = self.scene
        prisms: dict[str, tuple[PrismGeometry, PrismBuffers]] = {}
        for fog in scene.fogs:
            bottom = mesh.points[:, 2] if fog.bottom == "terrain" else mesh.layers[fog.bottom]
            geometry: PrismGeometry = (mesh.points, bottom, mesh.layers[fog.top], mesh.triangles)
            prisms[fog.name] = (geometry, prism_buffers(*geometry, layer=fog.layer))
        return prisms

    def finish(self, request: NatureRequest, mesh: Optional[TerrainMesh], frame: GLNatureFrame,
               stats: dict[str, float]) -> dict[str, float]:
        """GUI thread: the terrain mesh (made VTK poly data here) and the vertex buffers of the prisms and cloud
        tetrahedra made by ``compute`` to VTK (uploaded and drawn at the next render); ``upload_s``: seconds spent
        here."""
        t0 = time.perf_counter()
        self._show_terrain(mesh.to_pyvista() if mesh is not None else None)
        scene = self.scene
        # made in this order: the first frame moves nothing
        for kind, fog in scene.volume_order([float(v) for v in frame.eye]):
            if kind == "fog" and fog.name in frame.prisms:
                (points, bottom, top, triangles), buffers = frame.prisms[fog.name]
                if fog.name in self.layers:
                    self.layers[fog.name].set_geometry(points, bottom, top, triangles, buffers=buffers)
                else:
                    self.layers[fog.name] = GLFogLayer(self.plotter, points, bottom, top, triangles, fog.layer,
                                                       buffers=buffers)
            elif kind == "clouds" and frame.clouds is not None:
                if self.clouds is None:
                    assert scene.cloud_shading is not None and scene.cloud_lod is not None
                    self.clouds = CloudPTVolume(self.plotter, frame.clouds, scene.cloud_lod, scene.cloud_shading,
                                                scene.cloud_table)
                else:
                    self.clouds.set_frame(frame.clouds)
                update = self.clouds.last_update
                stats["cloud_leaves_added"] = float(update.added)
                stats["cloud_upload_bytes"] = float(update.upload_bytes)
                stats["cloud_upload_whole"] = float(update.whole)
        if (self.layers or self.clouds is not None) and not self._single_sample:
            # the float scene target and the volumes' targets are single-sample (gl_pt); a scene of terrain and sky
            # alone keeps the window's multisampling, as the CPU backend does without an overlay
            hold_single_sample(self.plotter, self)
            self._single_sample = True
        stats["fog_prisms"] = float(sum(layer.drawn for layer in self.layers.values()))
        self._sort_layers(frame.eye)
        stats["upload_s"] = time.perf_counter() - t0
        self.last_stats = stats
        self.shown_scale = 1
        return stats

    def _sort_layers(self, eye: np.ndarray) -> None:
        """The layers' actors in the renderer in the CPU's compositing order (``NatureScene.volume_order``)."""
        actors: list[Any] = []
        for kind, fog in self.scene.volume_order([float(v) for v in eye]):
            if kind == "fog" and fog.name in self.layers:
                actors += [self.layers[fog.name].actor, self.layers[fog.name].resolve_actor]
            elif kind == "clouds" and self.clouds is not None:
                actors += [self.clouds.actor, self.clouds.resolve_actor]
        props = self.plotter.renderer.GetViewProps()
        shown = [props.GetItemAsObject(i) for i in range(props.GetNumberOfItems())]
        position = {id(p): i for i, p in enumerate(shown)}
        now = [position.get(id(a), -1) for a in actors]
        if now != sorted(now):
            # moved in the renderer's prop list only: RemoveActor would release the actors' GL resources. (Moving
            # the GL PT actor before the renderer's first render left the whole image black on llvmpipe; the
            # actors are made in the first frame's order, so only later frames move them.)
            for actor in actors:
                props.RemoveItem(actor)
            for actor in actors:
                props.AddItem(actor)

    def remove(self) -> None:
        """Take the prisms, clouds, terrain and sky out of the plotter and free the GL targets (call before closing
        the plotter)."""
        for layer in self.layers.values():
            layer.remove()
        self.layers = {}
        if self.clouds is not None:
            self.clouds.remove()
            self.clouds = None
        self._terrain_worker.shutdown(wait=False)       # a frame in flight on it finishes on its own
        if self._single_sample:
            release_single_sample(self.plotter, self)
            self._single_sample = False
        super().remove()


#: the natural scene's view of either backend (what the controller keeps under "nature")
EitherNatureView = Union[NatureView, GLNatureView]
