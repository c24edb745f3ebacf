"""The natural scene on the GPU backend: terrain C-LOD, sky dome, ground fog / cloud layers and C-LOD clouds all
drawn by VTK's OpenGL pipeline into the scene's own depth buffer (Roettger Ch. 10-11, digest §8-9); the GPU side of
``volviz.render.nature_view.NatureView``, whose calls it keeps (``update``, ``begin`` / ``compute`` / ``finish``,
``remove``, ``last_stats``, ``scene`` for the bounds), so the controller and the app only choose the class
(``volviz.render.backend``, view kind "nature").

- Terrain with geomorphing and the sky dome: ``NatureView``'s VTK meshes, unchanged (this class is its subclass).
- Prism layers (ground fog, cloud layers between two height fields; §10.3-10.4): one ``volviz.render.gl_fog.
  GLFogLayer`` each, on the frame's C-LOD terrain triangles and morphed layer heights (``GLFogLayer.set_geometry``
  every frame: the prisms follow the terrain's LOD as on the CPU), reading the opaque depth of the terrain and sky.
- Clouds (§11.3-11.6): the frame's C-LOD leaves in their back-to-front order, one point each with its place and
  corner values (``cloud_buffers``); a geometry shader makes each leaf's 5 tetrahedra (split and ordered back to
  front as ``CloudFrame.to_tetmesh`` does) with the morphed table field, drawn by ``CloudPTVolume``, a
  ``volviz.render.gl_pt.GLPTVolume`` whose fragments
  scale the segment length by the second field as the CPU clouds do (Eq. 11.9, l' = l m̄ with m the modulating field
  over its maximum at the middle of the segment; NPR §11.6.2: the table is indexed by f, γ modulates), looked up in
  the scene's own cloud table (the CPU's, 64 x 64 x 128 over the root cube's diagonal).
- The layers are composited in ``NatureScene.volume_order`` (farthest layer first), the CPU's order: their actors
  are re-added to the renderer in that order when it changes.

``compute`` (any thread) does the LOD work and builds the vertex buffers as NumPy arrays, in two threads (the
Numba kernels release the GIL), each with half the caller's Numba threads (``volviz.numba_threads``): the terrain's
C-LOD mesh and each layer's per-point heights and emissions (``gl_fog.prism_buffers``; the prisms are made by a
geometry shader) on one, the clouds' refinement, morphing, leaf list and per-leaf texels (``cloud_buffers``, one
Numba pass over the leaves) on the other; ``finish`` (GUI thread) only hands them to VTK, sharing the arrays
(``vtk_facade.shared_polydata``), and VTK uploads them and draws everything at the next render, at the window's full
size (a preview ``scale`` is ignored). No image is made on the CPU.

What ``GLPTVolume`` lacks for the clouds (``CloudPTVolume`` works around it through its private members, listed
there): a per-cell length modulation attribute, a caller-given back-to-front order (the leaves' BSP order; MPVO would
sample the non-conforming leaf mesh's boundaries), a caller-given table (its own is built per mesh over the mesh's
longest edge), cells made on the GPU, and a public way to replace the mesh by a frame's buffers. Per frame the
clouds' buffers are rebuilt and uploaded whole, 96 bytes per leaf of 5 tetrahedra (``BYTES_PER_LEAF``,
``stats["cloud_upload_bytes"]``): a point (3 float32), 5 RGBA float32 texels in a buffer texture (``cloud_leaf_gs.
glsl``: the leaf's lowest grid point and edge, the table field and the modulating field at its 8 corners) and one
index. (Made on the CPU, the tetrahedra took 208 bytes each: 4 positions, 7 texels of face planes and affine forms,
12 indices; VTK's index buffer for 12 indices per tetrahedron was most of the upload.)

Errors against the CPU ``NatureView`` of the same camera and LOD (8-bit screen units), measured on llvmpipe in
``tests/test_render_gl_nature.py``: see the bounds there.
"""
from __future__ import annotations

import threading
import time
from concurrent.futures import ThreadPoolExecutor, wait
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Any, Callable

import numpy as np

from volviz.model.datasets import TetMesh
from volviz.nature.clouds import CloudFrame, CloudShading, CloudVolume
from volviz.nature.nature_scene import NatureScene
from volviz.numba_threads import numba_threads, share
from volviz.render.nature_view import NatureView
from volviz.render.gl_fog import GLFogLayer, prism_buffers
from volviz.render.gl_pt import GLPTVolume, _resolve_polydata, shader_source
from volviz.render.image_overlay import hold_single_sample, release_single_sample
from volviz.unstructured.topology import visible_ranges

__all__ = ["CloudBuffers", "CloudPTVolume", "GLNatureView", "cloud_buffers", "modulation_scale"]

#: bytes uploaded per leaf (5 tetrahedra): its lowest corner (3 float32), 5 RGBA float32 texels, 1 index
BYTES_PER_LEAF = 3 * 4 + 5 * 16 + 4

# (anchor in gl_pt's fragment shader, text added after it): the modulation's flat varying, and the length scaled by
# the modulating field at the middle of the clipped segment
_FS_PATCH = (("flat in vec4 cellRange;", "\nflat in vec4 cellModulate;"),
             ("float len = (t1 - t0) * length(d);",
              "\n  len *= max(dot(cellModulate.xyz, o + 0.5 * (t0 + t1) * d) + cellModulate.w, 0.0);"))


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


@dataclass
class CloudBuffers:
    """A frame's cloud buffers as NumPy arrays (``cloud_buffers``, any thread): ``points`` (L + 2, 3) float32, the
    leaves' lowest corners relative to ``centre`` (the cloud volume's) and the volume's box (for VTK's bounds),
    ``texels`` (L, 5, 4) float32 per leaf (``_cloud_buffer_kernels.N_TEXELS``: ``cloud_leaf_gs.glsl`` makes the
    leaf's tetrahedra from them), ``visible`` (L,) the leaves with some opacity under the cloud TF; the leaves are in
    back-to-front order. ``bounds`` (3, 2): the volume's box relative to the centre; ``origin`` and ``spacing``: the
    grid's, the origin relative to the centre."""

    points: np.ndarray
    texels: np.ndarray
    visible: np.ndarray
    centre: np.ndarray
    bounds: np.ndarray
    origin: np.ndarray
    spacing: np.ndarray

    @property
    def n_leaves(self) -> int:
        return int(len(self.visible))


def cloud_buffers(frame: CloudFrame, shading: CloudShading, m_scale: float) -> CloudBuffers:
    """Any thread (Numba, releasing the GIL): the buffers of ``CloudPTVolume`` for a frame's leaves in their
    back-to-front order: each leaf's place and its corners' morphed table field and modulating field over
    ``m_scale`` (``modulation_scale``; ``_cloud_buffer_kernels.leaf_buffer``), and the TF's culling from each leaf's
    range of the table field (a leaf is kept if one of its tetrahedra has some opacity)."""
    from volviz.render._cloud_buffer_kernels import leaf_buffer

    vol = frame.lod.volume
    vf, vg = frame.lod.morphed
    table, other = (vf, vg) if shading.table_field == "f" else (vg, vf)
    origin = np.asarray(vol.origin, np.float64)
    spacing = np.asarray(vol.spacing, np.float64)
    centre = origin + 0.5 * (np.asarray(vol.shape, np.float64) - 1.0) * spacing
    pos, texels, ranges = leaf_buffer(np.ascontiguousarray(frame.leaves, np.int64), int(vol.root),
                                      np.asarray(vol.shape, np.int64), origin, spacing, centre, table.reshape(-1),
                                      other.reshape(-1), float(m_scale))
    half = 0.5 * (np.asarray(vol.shape, np.float64) - 1.0) * spacing
    pos[-2:] = [-half, half]
    visible = visible_ranges(ranges[:, 0], ranges[:, 1], shading.tf.scalars, shading.tf.extinction)
    return CloudBuffers(pos, texels, visible, centre, np.stack([-half, half], axis=1), origin - centre, spacing)


@dataclass
class _FrameGeometry:
    """What ``GLPTVolume``'s draw reads of its ``topo`` for a frame drawn in a given order: the actor's origin (the
    ray basis is taken relative to it) and the number of cells it orders (here the leaves)."""

    origin: np.ndarray
    n_tets: int


class CloudPTVolume(GLPTVolume):
    """C-LOD cloud leaves on the GPU PT pass (module docstring): the shading's table, the length modulated per
    fragment (Eq. 11.9), the given back-to-front order of the leaves, and ``set_frame`` for the next frame's buffers:
    one point per leaf, drawn in that order, whose texels (a buffer texture) the geometry shader makes the leaf's 5
    tetrahedra from (``cloud_leaf_gs.glsl``), uploaded at the next render.

    Private members of ``GLPTVolume`` used (what a public API would replace): ``_build_table`` (overridden to return
    the scene's table), ``_set_index_buffer`` (overridden: one index per leaf), ``_sorted`` / ``_sorted_key`` /
    ``_order_key`` (the given order, kept by ``reuse_order``), ``_vis`` (culling of the new frame), ``topo``
    (``_FrameGeometry``: a frame has no mesh topology), ``_on_update_shader`` / ``_on_end`` (extended to bind the
    leaf texture and set the grid and eye uniforms)."""

    def __init__(self, plotter: Any, buffers: CloudBuffers, shading: CloudShading, table: Any) -> None:
        from volviz.render.vtk_facade import vtk

        self._cloud_table = table
        self._texels: Any = None              # the frame's leaf texels as a VTK array, until uploaded
        self._leaf_buffer: Any = None         # their GL buffer and buffer texture
        self._leaf_texture: Any = None
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
        self.set_frame(buffers)

    def _build_table(self) -> Any:
        return self._cloud_table

    def set_frame(self, buffers: CloudBuffers) -> None:
        """The next frame's leaves (back to front) as ``cloud_buffers`` made them: new points (shared with VTK) and
        texels (uploaded to the buffer texture at the next render), their own order for every camera, the same
        table."""
        from volviz.render.vtk_facade import numpy_to_vtk, shared_polydata

        self.topo = _FrameGeometry(np.asarray(buffers.centre, np.float64), buffers.n_leaves)  # type: ignore[assignment]
        self._vis = buffers.visible
        self._grid = (np.asarray(buffers.origin, np.float64), np.asarray(buffers.spacing, np.float64))
        self.polydata = shared_polydata(buffers.points, {})
        self.mapper.SetInputData(self.polydata)
        texels = buffers.texels.reshape(-1, 4) if buffers.n_leaves else np.zeros((1, 4), np.float32)
        self._texels = numpy_to_vtk(np.ascontiguousarray(texels), deep=False)
        self._texels_ref = texels             # numpy_to_vtk(deep=False) needs the array kept alive
        self.actor.SetPosition(*buffers.centre)
        self.resolve_mapper.SetInputData(_resolve_polydata(buffers.bounds))    # VTK culls the resolve by these
        self.resolve_actor.SetPosition(*buffers.centre)
        self.reuse_order = True
        self._sorted = np.arange(buffers.n_leaves, dtype=np.int64)
        self._sorted_key = self._order_key = None

    def _set_index_buffer(self, cells: np.ndarray) -> None:
        """Draw the leaves ``cells`` in this order from the next render on: one point each (32-bit indices shared
        with VTK, kept referenced here)."""
        from volviz.render.vtk_facade import numpy_to_vtk, vtk

        conn = np.ascontiguousarray(cells, dtype=np.int32)
        offsets = np.arange(len(conn) + 1, dtype=np.int32)
        self._cell_arrays = (offsets, conn)
        verts = vtk.vtkCellArray()
        verts.SetData(numpy_to_vtk(offsets, deep=False), numpy_to_vtk(conn, deep=False))
        self.polydata.SetVerts(verts)
        self.polydata.Modified()

    def _on_update_shader(self, program: Any) -> None:
        """gl_pt's uniforms and textures, the frame's leaf texels as the buffer texture ``cloudLeaves`` (uploaded
        when the frame changed), and the grid and the eye in model coordinates for the geometry shader."""
        from volviz.render.vtk_facade import vtk

        super()._on_update_shader(program)
        if program is None:
            return
        ren_win = self.renderer.GetRenderWindow()
        if self._texels is not None:
            if self._leaf_buffer is None:
                self._leaf_buffer = vtk.vtkOpenGLVertexBufferObject()
                self._leaf_buffer.SetDataType(vtk.VTK_FLOAT)
                self._leaf_buffer.SetCoordShiftAndScaleMethod(0)     # the raw floats, no shift or scale
                self._leaf_texture = vtk.vtkTextureObject()
                self._leaf_texture.SetContext(ren_win)
            self._leaf_buffer.UploadDataArray(self._texels)
            self._leaf_texture.CreateTextureBuffer(self._texels.GetNumberOfTuples(), 4, vtk.VTK_FLOAT,
                                                   self._leaf_buffer)
            self._texels = None
        self._leaf_texture.Activate()
        program.SetUniformi("cloudLeaves", self._leaf_texture.GetTextureUnit())
        origin, spacing = self._grid
        eye = np.asarray(self.renderer.GetActiveCamera().GetPosition(), np.float64) - self.topo.origin
        program.SetUniform3f("cloudOrigin", [float(v) for v in origin])
        program.SetUniform3f("cloudSpacing", [float(v) for v in spacing])
        program.SetUniform3f("cloudEye", [float(v) for v in eye])

    def _on_end(self, *args: Any) -> None:
        super()._on_end(*args)
        if self._leaf_texture is not None:
            self._leaf_texture.Deactivate()

    def remove(self) -> None:
        """GLPTVolume's ``remove`` and the cell texture's GL resources."""
        ren_win = self.renderer.GetRenderWindow()
        if ren_win is not None and self._leaf_texture is not None:
            self._leaf_texture.ReleaseGraphicsResources(ren_win)
            self._leaf_buffer.ReleaseGraphicsResources()
        self._leaf_texture = self._leaf_buffer = None
        super().remove()


class GLNatureView(NatureView):
    """A ``NatureScene`` in a PyVista plotter, fog and clouds on the GPU (module docstring). ``layers``: the
    ``GLFogLayer`` of each prism layer by name; ``clouds``: the ``CloudPTVolume`` (None without clouds or before the
    first frame)."""

    backend = "gpu"

    def __init__(self, plotter: Any, scene: NatureScene, size: tuple[int, int] | None = None,
                 filter_texture: bool | None = None) -> None:
        super().__init__(plotter, scene, size, filter_texture)
        self.layers: dict[str, GLFogLayer] = {}
        self.clouds: CloudPTVolume | None = None
        self._m_scale: float | None = None
        # the terrain half of ``compute``: one thread kept for the view's life (a new thread each frame would also
        # make Numba's OpenMP start a new team of threads for it each frame)
        self._terrain_worker = ThreadPoolExecutor(max_workers=1, thread_name_prefix="volviz-terrain-lod")
        self._single_sample = False             # held once a fog layer or the clouds draw (``finish``)

    def compute(self, request: tuple[Any, tuple[int, int], int],
                progress: Any = None) -> tuple[Any, Any, dict[str, float]]:
        """Any thread: the LOD work of a frame (no image): the terrain's C-LOD mesh as VTK poly data and as the
        ``TerrainMesh`` the prisms stand on with each prism layer's vertex buffer (``prism_buffers``), on a second
        thread meanwhile the clouds' refinement, morphing and vertex buffer (``cloud_buffers``; both parts run
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
                    frame = scene.cloud_lod.update(cam, size)
                    if self._m_scale is None:
                        self._m_scale = modulation_scale(scene.cloud_lod.volume, scene.cloud_shading)
                    clouds = cloud_buffers(frame, scene.cloud_shading, self._m_scale)
                    stats["cloud_tets"] = float(frame.n_tets)
                    stats["cloud_upload_bytes"] = float(clouds.n_leaves * BYTES_PER_LEAF)
            except BaseException:
                clouds_done.set()
                wait([terrain])                    # no terrain work left behind
                raise
            clouds_done.set()
            mesh, poly, prisms = terrain.result()
        if mesh is not None:
            stats["terrain_triangles"] = float(mesh.n_triangles)
        stats["lod_s"] = time.perf_counter() - t0
        return poly, SimpleNamespace(mesh=mesh, clouds=clouds, prisms=prisms,
                                     eye=np.asarray(cam.position, np.float64)), stats

    def _terrain_part(self, cam: Any, size: tuple[int, int], threads: Callable[[], int]
                      ) -> tuple[Any, Any, dict[str, Any]]:
        """The terrain's C-LOD mesh, as VTK poly data, and each prism layer's (geometry, ``prism_buffers``), their
        kernels on ``threads()`` Numba threads (asked for when each stage starts)."""
        scene = self.scene
        with numba_threads(threads()):
            mesh = scene.terrain_mesh(cam, size, emit_threads=threads)
        if mesh is None:
            return None, None, {}
        with numba_threads(threads()):
            return mesh, mesh.to_pyvista(), self._prism_layers(mesh)

    def _prism_layers(self, mesh: Any) -> dict[str, Any]:
        """Each prism layer's (geometry, ``prism_buffers``) on the terrain ``mesh``, by name."""
        scene = self.scene
        prisms = {}
        for fog in scene.fogs:
            bottom = mesh.points[:, 2] if fog.bottom == "terrain" else mesh.layers[fog.bottom]
            geometry = (mesh.points, bottom, mesh.layers[fog.top], mesh.triangles)
            prisms[fog.name] = (geometry, prism_buffers(*geometry, layer=fog.layer))
        return prisms

    def finish(self, request: tuple[Any, tuple[int, int], int], poly: Any, frame: Any,
               stats: dict[str, float]) -> dict[str, float]:
        """GUI thread: the terrain mesh and the vertex buffers of the prisms and cloud tetrahedra made by ``compute``
        to VTK (uploaded and drawn at the next render); ``upload_s``: seconds spent here."""
        t0 = time.perf_counter()
        self._show_terrain(poly)
        scene = self.scene
        for kind, fog in scene.volume_order(frame.eye):    # made in this order: the first frame moves nothing
            if kind == "fog" and fog.name in frame.prisms:
                (points, bottom, top, triangles), buffers = frame.prisms[fog.name]
                if fog.name in self.layers:
                    self.layers[fog.name].set_geometry(points, bottom, top, triangles, buffers=buffers)
                else:
                    self.layers[fog.name] = GLFogLayer(self.plotter, points, bottom, top, triangles, fog.layer,
                                                       buffers=buffers)
            elif kind == "clouds" and frame.clouds is not None:
                if self.clouds is None:
                    assert scene.cloud_shading is not None
                    self.clouds = CloudPTVolume(self.plotter, frame.clouds, scene.cloud_shading, scene.cloud_table)
                else:
                    self.clouds.set_frame(frame.clouds)
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
