"""Ground fog and cloud layers (prisms on the terrain triangles) drawn by VTK's OpenGL pipeline with volviz's shaders:
PCP, Roettger §10.3 (the three-pass recipe) and §10.4 (the near-plane cap, the MIP variant); the GPU side of
``volviz.nature.fog.render_layer``, the same layer, emission field and modes.

    fog = GLFogLayer(plotter, points, bottom, top, triangles, FogLayer(mode="attenuated"))
    plotter.screenshot()                # terrain, sky and other props are ordinary VTK props of the same renderer

A geometry shader makes each terrain triangle's prism; each back face's fragment integrates the prism's segment of
its pixel ray (cut by the near plane and the opaque depth) and adds it, unsorted, into the layer's float32 target,
which a resolve quad converts (emissive, attenuated, MIP) and blends over the scene. How a frame is drawn and what is
not handled: docs/gl-passes.md "gl_fog: ground fog and cloud layers (Roettger §10.3-10.4)"; errors and timings:
docs/bench/gl-passes.md "gl_fog". The window should be single-sample (the float target is). Call ``remove()`` before
closing the plotter.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from volviz.model.camera import Camera
from volviz.nature.fog import FogLayer, layer_emission
from volviz.render._prism_kernels import kept_connectivity, layer_buffer
from volviz.render.gl import ScenePass, color_target, glenum, release, set_ray_uniforms, shader_source

if TYPE_CHECKING:   # type-only: PyVista's plotter, the natural scene's terrain mesh
    import pyvista as pv

    from volviz.nature.terrain import TerrainMesh

__all__ = ["GLFogLayer", "PrismBuffers", "add_fog_layer", "layer_values", "prism_buffers"]

_MODES = {"emissive": 0, "attenuated": 1, "mip": 2}
_ATTRIBUTES = ("fogValue",)


def layer_values(points: np.ndarray, bottom: np.ndarray, top: np.ndarray, emission_bottom: np.ndarray,
                 emission_top: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The layer's centre (3,) (of the bounding box of its points between bottom and top), the points relative to it
    as float32 (n + 2, 3) (x, y; z the bottom height; then the box's two corners, in no triangle, so that VTK's
    bounds hold the whole layer), the four per-point values as float32 (n + 2, 4) (bottom and top height relative
    to the centre, bottom and top emission; 0 at the corners) and the box relative to the centre (3, 2)."""
    pts = np.ascontiguousarray(points, dtype=np.float64)
    zb, zt, eb, et = (np.ascontiguousarray(a, dtype=np.float64) for a in (bottom, top, emission_bottom, emission_top))
    lo, hi, rel, values = layer_buffer(pts, zb, zt, eb, et)
    centre = 0.5 * (lo + hi)
    return centre, rel, values, np.stack([lo - centre, hi - centre], axis=1)


@dataclass
class PrismBuffers:
    """A layer's vertex buffer as NumPy arrays (``prism_buffers``), made on any thread and handed to VTK without a
    copy (``GLFogLayer.set_buffers``): the terrain triangles' ``points`` (n, 3) float32 relative to ``centre``, their
    ``attributes`` (``fogValue``: (n, 4) float32, bottom and top height and emission), ``connectivity`` (3m,) int32
    (the triangles; the geometry shader makes each one's prism), ``bounds`` (3, 2) relative to the centre, ``drawn``
    = the prisms kept (with area, thickness and some emission)."""

    points: np.ndarray
    attributes: dict[str, np.ndarray]
    connectivity: np.ndarray
    centre: np.ndarray
    drawn: int
    bounds: np.ndarray

    def first_prism(self) -> "PrismBuffers":
        """The same buffers drawing only the first prism (or none): a draw with the prisms' own work removed."""
        return PrismBuffers(self.points, self.attributes, self.connectivity[:3].copy(), self.centre,
                            min(self.drawn, 1), self.bounds)


def prism_buffers(points: np.ndarray, bottom: np.ndarray, top: np.ndarray, triangles: np.ndarray, layer: FogLayer,
                  emission: tuple[np.ndarray, np.ndarray] | None = None) -> PrismBuffers:
    """Any thread: the vertex buffer of the layer's prisms, one per terrain triangle: per point its xy and the bottom
    and top heights and emissions of ``layer``'s mode (``volviz.nature.fog.layer_emission``); the prisms themselves
    (side planes, affine forms, 8 triangles wound outward) are made per triangle by the geometry shader
    (``fog_prism_gs.glsl``). Triangles whose prism has no area, no thickness or all six emissions <= 0 are left out
    here (``_prism_kernels.kept_connectivity``, the shader's own test, which it also applies), as the CPU PCP leaves
    them out: ``drawn`` prisms, 3 indices each in ``connectivity``."""
    points, bottom, top = (np.asarray(a, dtype=np.float64) for a in (points, bottom, top))
    eb, et = layer_emission(bottom, top, layer, emission)
    centre, rel, values, bounds = layer_values(points, bottom, top, eb, et)
    tris = np.ascontiguousarray(triangles).reshape(-1, 3)
    if tris.dtype.kind not in "iu":
        tris = tris.astype(np.int64)
    kept = kept_connectivity(rel, values, tris)
    return PrismBuffers(rel, {"fogValue": values}, kept, centre, len(kept) // 3, bounds)


def _resolve_polydata(bounds: np.ndarray) -> Any:
    """The resolve's geometry: the 8 corners of ``bounds`` (3, 2) in the actor's bounds (for VTK's culling) and one
    triangle whose ``fogCorner`` attribute covers the viewport in normalised device coordinates (the other corners'
    is (0, 0): the bounds' zero-area triangle stays one)."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import box_corners_polydata, numpy_to_vtk

    pd = box_corners_polydata(bounds, [(0, 1, 2)])
    ndc = np.zeros((8, 2), np.float32)
    ndc[:3] = [[-1.0, -1.0], [3.0, -1.0], [-1.0, 3.0]]
    va = numpy_to_vtk(ndc, deep=True)
    va.SetName("fogCorner")
    pd.GetPointData().AddArray(va)
    return pd


class GLFogLayer:
    """One prism layer (ground fog or cloud layer) drawn on the GPU in a PyVista plotter's renderer (module
    docstring). Arguments as ``volviz.nature.fog.render_layer``: terrain ``points`` (n, 3) (x, y used), per-vertex
    ``bottom`` and ``top`` heights, ``triangles`` (m, 3), the ``layer``'s optics and ``emission`` = (e_bottom, e_top)
    per vertex (default 1 where the layer has thickness). ``drawn``: the number of prisms uploaded (after
    zero-emission culling; the CPU's count also leaves out prisms off the screen). ``set_layer`` changes color,
    density, gain or mode."""

    def __init__(self, plotter: Any, points: np.ndarray, bottom: np.ndarray, top: np.ndarray,
                 triangles: np.ndarray, layer: FogLayer, emission: tuple[np.ndarray, np.ndarray] | None = None,
                 buffers: PrismBuffers | None = None) -> None:
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import shader_observer, vtk

        self.plotter = plotter
        self.renderer = plotter.renderer
        self._geometry = (np.asarray(points, dtype=np.float64), np.asarray(bottom, dtype=np.float64),
                          np.asarray(top, dtype=np.float64), np.asarray(triangles, dtype=np.int64))
        self._emission = emission
        self.layer = layer
        self._accum: Any = None
        self._fbo: Any = None
        self._depth_tex: Any = None
        self._bound = False                   # the layer's target is bound (prisms drawn, resolve not yet)
        self._equation: list[int] | None = None
        self._visible = True                  # shown (the actors also hide while no prism is drawn)

        self.mapper = vtk.vtkOpenGLPolyDataMapper()
        self.mapper.ScalarVisibilityOff()
        # the geometry shader places the prisms' corners from vertexMC's xy and fogValue's heights in one frame
        self.mapper.SetVBOShiftScaleMethod(vtk.vtkPolyDataMapper.DISABLE_SHIFT_SCALE)
        for name in _ATTRIBUTES:
            self.mapper.MapDataArrayToVertexAttribute(name, name, vtk.vtkDataObject.FIELD_ASSOCIATION_POINTS, -1)
        self.actor = self._translucent_actor(self.mapper, "fog_prism_vs.glsl", "fog_prism_fs.glsl",
                                             "fog_prism_gs.glsl")
        self.actor.GetProperty().FrontfaceCullingOn()
        self.resolve_mapper = vtk.vtkOpenGLPolyDataMapper()
        self.resolve_mapper.ScalarVisibilityOff()
        self.resolve_mapper.MapDataArrayToVertexAttribute("fogCorner", "fogCorner",
                                                          vtk.vtkDataObject.FIELD_ASSOCIATION_POINTS, -1)
        self.resolve_actor = self._translucent_actor(self.resolve_mapper, "fog_resolve_vs.glsl",
                                                     "fog_resolve_fs.glsl")
        if buffers is None:
            self._upload()
        else:
            self.set_buffers(buffers)

        self.scene_pass = ScenePass.acquire(self.renderer, self)   # the shared float target and opaque depth
        self._observers = [
            (self.mapper, self.mapper.AddObserver(vtk.vtkCommand.UpdateShaderEvent,
                                                  shader_observer(self._on_prisms))),
            (self.resolve_mapper, self.resolve_mapper.AddObserver(vtk.vtkCommand.UpdateShaderEvent,
                                                                  shader_observer(self._on_resolve))),
            (self.renderer, self.renderer.AddObserver(vtk.vtkCommand.EndEvent, self._on_end)),
        ]
        self.renderer.AddActor(self.actor)
        self.renderer.AddActor(self.resolve_actor)

    # --- set-up --------------------------------------------------------------------------------------------------
    @staticmethod
    def _translucent_actor(mapper: Any, vs: str, fs: str, gs: str | None = None) -> Any:
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import premultiplied_texture, vtk

        sp = vtk.vtkShaderProperty()
        sp.SetVertexShaderCode(shader_source(vs))
        sp.SetFragmentShaderCode(shader_source(fs))
        if gs is not None:
            sp.SetGeometryShaderCode(shader_source(gs))
        actor = vtk.vtkActor()
        actor.SetMapper(mapper)
        actor.SetShaderProperty(sp)
        actor.ForceTranslucentOn()
        actor.SetTexture(premultiplied_texture())
        return actor

    def _upload(self) -> None:
        """The layer's vertex buffer and the resolve triangle for the current layer (its mode picks the emission)."""
        self.set_buffers(prism_buffers(*self._geometry, self.layer, self._emission))

    def set_buffers(self, buffers: PrismBuffers) -> None:
        """GUI thread: show a ``prism_buffers`` result (made for this layer's optics, e.g. on a worker for the next
        frame's C-LOD triangles): the prisms' and the resolve's poly data to the mappers, uploaded at the next
        render."""
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import shared_polydata

        pd = shared_polydata(buffers.points, buffers.attributes, buffers.connectivity)
        self.drawn = buffers.drawn
        centre = self.centre = buffers.centre
        self.mapper.SetInputData(pd)
        self.actor.SetPosition(*centre)
        self.resolve_mapper.SetInputData(_resolve_polydata(buffers.bounds if self.drawn else np.zeros((3, 2))))
        self.resolve_actor.SetPosition(*centre)
        on = self.drawn > 0 and self._visible
        self.actor.SetVisibility(on)
        self.resolve_actor.SetVisibility(on)

    # --- per frame -----------------------------------------------------------------------------------------------
    def _target(self, w: int, h: int) -> Any:
        """The layer's (w, h) single-channel float32 target (made again when the renderer's size changes)."""
        if self._accum is None or (self._accum.GetWidth(), self._accum.GetHeight()) != (w, h):
            self._release_target()
            self._accum, self._fbo = color_target(self.renderer.GetRenderWindow(), w, h, 1, False)
        return self._fbo

    def _on_prisms(self, program: Any) -> None:
        """The prisms' draw: bind and clear the layer's target, set the blend equation (MIP: MAX), the uniforms."""
        w, h = (int(v) for v in self.renderer.GetSize())
        state = self.renderer.GetRenderWindow().GetState()
        fbo = self._target(w, h)
        fbo.SaveCurrentBindingsAndBuffers()
        fbo.Bind()
        fbo.ActivateDrawBuffer(0)
        self._bound = True
        state.vtkglClearColor(0.0, 0.0, 0.0, 0.0)
        state.vtkglClear(glenum.COLOR_BUFFER_BIT)
        if self.layer.mode == "mip":
            rgb, alpha = [0], [0]
            state.vtkglGetIntegerv(glenum.BLEND_EQUATION_RGB, rgb)
            state.vtkglGetIntegerv(glenum.BLEND_EQUATION_ALPHA, alpha)
            self._equation = [rgb[0], alpha[0]]
            state.vtkglBlendEquation(glenum.MAX)
        cam = Camera.from_pyvista(self.renderer.GetActiveCamera())
        rb = cam.rays((w, h), origin=self.centre)
        set_ray_uniforms(program, rb, h, cam.clipping_range, False)
        program.SetUniformi("mipMode", int(self.layer.mode == "mip"))
        depth = self.scene_pass.depth_texture()
        depth.Activate()
        self._depth_tex = depth
        program.SetUniformi("opaqueDepth", depth.GetTextureUnit())

    def _restore(self) -> None:
        """The scene's framebuffer and blend equation again."""
        if self._bound:
            self._fbo.RestorePreviousBindingsAndBuffers()
            self._bound = False
        if self._equation is not None:
            self.renderer.GetRenderWindow().GetState().vtkglBlendEquationSeparate(*self._equation)
            self._equation = None
        if self._depth_tex is not None:
            self._depth_tex.Deactivate()
            self._depth_tex = None

    def _on_resolve(self, program: Any) -> None:
        """The resolve's draw: back to the scene's target; the layer's sum (or maximum) becomes RGBA."""
        self._restore()
        self._accum.Activate()
        program.SetUniformi("fogAccum", self._accum.GetTextureUnit())
        program.SetUniformi("fogMode", _MODES[self.layer.mode])
        program.SetUniform3f("fogColor", [float(x) for x in self.layer.color])
        program.SetUniformf("fogDensity", float(self.layer.density))
        program.SetUniformf("fogGain", float(self.layer.mip_gain))

    def _on_end(self, *_: Any) -> None:
        self._restore()                        # only if the resolve did not draw (it always follows the prisms)
        if self._accum is not None:
            self._accum.Deactivate()

    def _release_target(self) -> None:
        release(self.renderer.GetRenderWindow(), (self._fbo, self._accum))
        self._fbo = self._accum = None

    # --- public --------------------------------------------------------------------------------------------------
    def set_layer(self, layer: FogLayer) -> None:
        """New optics; a change into or out of the MIP mode changes the emission field (a new upload)."""
        remake = (layer.mode == "mip") != (self.layer.mode == "mip")
        self.layer = layer
        if remake:
            self._upload()

    def set_geometry(self, points: np.ndarray, bottom: np.ndarray, top: np.ndarray, triangles: np.ndarray,
                     emission: tuple[np.ndarray, np.ndarray] | None = None, buffers: PrismBuffers | None = None
                     ) -> None:
        """New prisms (arguments as the constructor's), e.g. the next frame's C-LOD terrain triangles: the vertex
        buffer is built (unless ``buffers``, ``prism_buffers`` of the same arguments, were made elsewhere) and
        uploaded again (the triangles' vertices, 7 floats each); the target stays."""
        self._geometry = (np.asarray(points, dtype=np.float64), np.asarray(bottom, dtype=np.float64),
                          np.asarray(top, dtype=np.float64), np.asarray(triangles, dtype=np.int64))
        self._emission = emission
        if buffers is None:
            self._upload()
        else:
            self.set_buffers(buffers)

    @property
    def visible(self) -> bool:
        return self._visible

    @visible.setter
    def visible(self, on: bool) -> None:
        self._visible = bool(on)
        self.actor.SetVisibility(self._visible and self.drawn > 0)
        self.resolve_actor.SetVisibility(self._visible and self.drawn > 0)

    def remove(self) -> None:
        """Take the layer out of the renderer; the last GL user of the renderer removes the float target."""
        for obj, tag in self._observers:
            obj.RemoveObserver(tag)
        self._observers = []
        self.renderer.RemoveActor(self.actor)
        self.renderer.RemoveActor(self.resolve_actor)
        self._release_target()
        self.scene_pass.release(self)


def add_fog_layer(plotter: pv.BasePlotter, mesh: TerrainMesh, layer: FogLayer, top: str, bottom: str = "terrain",
                  emission: tuple[np.ndarray, np.ndarray] | None = None) -> GLFogLayer:
    """A GPU fog layer on a terrain mesh as the natural scene holds it (``TerrainMesh``: ``points``, ``triangles``
    and named height ``layers``): from the terrain (``bottom="terrain"``) or a named layer up to the layer ``top``."""
    bot = mesh.points[:, 2] if bottom == "terrain" else mesh.layers[bottom]
    return GLFogLayer(plotter, mesh.points, bot, mesh.layers[top], mesh.triangles, layer, emission)
