"""Pre-integrated projected tetrahedra drawn by VTK's OpenGL pipeline with volviz's own shaders (Roettger Ch. 8-9,
digest §6-7: cell projection in visibility order with a pre-integration table lookup per fragment).

    vol = GLPTVolume(plotter, mesh, tf)          # a TetMesh and a TransferFunction
    plotter.show() / plotter.screenshot()          # every render sorts for the camera of that render
    vol.set_tf(tf2)                                # replaces only the table texture

How a frame is drawn:

- Mesh data is uploaded once: a static vertex buffer with 4 vertices per tetrahedron, each carrying its cell's four
  face planes (n . x <= d inside), the scalar's affine form s(x) = g . x + c and the cell's scalar range, all relative
  to the mesh's centre (``topology``: meshes offset by 1e6 keep their precision; the actor is placed at the centre).
- Per render (the renderer's ``StartEvent``): the back-to-front cell order for the camera (``visibility_order``, as
  the CPU ``pt``) with zero-opacity and NaN cells culled (Roettger §9.1) becomes the index buffer, 4 triangles per
  cell, as 32-bit arrays shared with VTK (no copy); nothing else is uploaded.
- Per fragment (``resources/shaders/pt_tet_fs.glsl``): only back (exit) faces are rasterised (front faces culled),
  so a cell cut by the near plane (camera inside the mesh) is still drawn. The pixel ray is rebuilt from
  ``gl_FragCoord`` with the camera's affine ray basis (no interpolated varyings), clipped against the cell's planes,
  the near and far planes and the opaque scene's depth at the pixel; the exact (s_f, s_b, l) of that segment look up
  the 3D table (Roettger §8.4, trilinear) or the separable one (§9.1: exact opacity 1 - exp(-l rho_hat), color
  polynomial in l; its layers a 2D texture array, bilinear within a layer), both float32. The fragment shader is
  made for one kind of segment evaluation (``PT_KIND``: 3D table, separable table, isosurfaces, pre-classified; VTK
  recompiles it when the kind changes):
  llvmpipe runs every branch of a fragment shader under a lane mask, so a run-time switch between kinds made every
  fragment pay for all of them (measured at 512^2 on the Blunt Fin: 3.7 s per frame with the four kinds behind a
  uniform, 1.8 s with the two table kinds, 1.4 s with the 3D table alone).
- Compositing: the cells are composited back to front with premultiplied "over" (ONE, ONE_MINUS_SRC_ALPHA, set
  and restored by VTK through a 1x1 premultiplied actor texture) into the volume's own float32 RGBA target, cleared
  to transparent black each frame (~95 cells overlap per pixel on the Blunt Fin, which an 8-bit target does not
  accumulate accurately). A second actor drawn right after the cells (``resolve_actor``: one triangle covering the
  viewport, with the volume's bounds so that VTK culls both together) binds the scene's framebuffer again and
  composites that image "over" the scene. Both actors are translucent and drawn in order (no OIT, no depth peeling
  for this renderer); other props of the renderer are drawn by VTK as usual (a translucent prop added later is
  blended over the volume; pixels the volume does not cover are the scene's).
- Opaque geometry: when the cells draw (translucent pass, after the opaque one), the depth buffer of the framebuffer
  being drawn holds the opaque scene (translucent props do not write depth); it is blitted into the volume's own
  depth texture, which the shader reads (texelFetch): each segment ends at the opaque depth of its pixel, so a cell
  straddling a surface is integrated only up to it. The volume's color target has no depth attachment, so GL's depth
  test never drops a fragment whose exit face lies behind the surface.
- Multisampling: by default the window's multisampling is switched off while the volume is in it (one color per
  pixel, as volviz's CPU overlays: the two backends then give the same viewport image), and the renderer draws
  into a float32 scene target (a ``vtkFramebufferPass``, ``_install_pass``, shared with ``volviz.render.gl_fog``'s
  layers, which read its depth texture; the volume itself does not need it and blits its depth from it). With
  ``keep_multisampling=True`` it stays on and no scene target is installed (its single-sample texture would undo
  the antialiasing, as it does when a fog layer in the same renderer installs one): the opaque scene (and
  translucent props) are antialiased in the window's multisampled framebuffer as without the volume, the depth blit
  resolves the opaque depth to one sample per pixel, and the resolve composites the volume's single-sample image
  over every sample. Measured on llvmpipe (4 samples,
  ``tests/test_render_gl_pt.py``): against the reference clipped at the single-sample depth over the antialiased
  opaque image, RMSE 0.32 / max 2.6 away from an opaque sphere's silhouette; on silhouette pixels (partly covered)
  up to 37 and next to them up to 6.5, since the volume is integrated to one sample's depth rather than each
  sample's (exact there would need per-sample shading of every cell).

- While the camera moves (``set_interactive``; by default while the window's desired update rate is VTK's
  interactive one, which VTK's interactor styles set for a drag and the app for playback) the cells are drawn into a
  smaller float target, at most ``interactive_pixels`` (1920x1080) pixels with the window's aspect
  (``volviz.render.reduced_fill``: a drag at 3840x2160 fills what one at 1920x1080 does; at 1080p or less nothing
  changes): the viewport, the pixel rays and the copy of the opaque depth (nearest sample) follow the smaller size,
  and the resolve samples the target bilinearly over the window (a variant of its shader, ``PT_UPSAMPLE``). The
  frame after the camera stops is drawn at full resolution, exactly as before. What that costs in image error during a
  drag, and what it saves in fill: ``volviz bench unstructured`` (docs/bench/unstructured.md).

Clipping planes and a box crop (``set_clip_planes``) cut each fragment's ray segment, as the near plane does.

Exact segments instead of a table (as the CPU ``pt``; the same fragment, ray and compositing): ``iso`` draws
isosurfaces (Roettger §8.8-8.10) by the §8.13 Heaviside limit of each fragment's segment (H(0) = 1/2, the surfaces
crossed composited in ray order with the color of the side seen, only cells an isovalue crosses drawn), with
``iso_shading="smooth"`` shaded by a headlight through vertex normals (§8.9: the intensity linear in the cell through
its barycentric coordinates, which are the face planes scaled per cell, taken where the ray crosses the surface);
``classification="pre"`` (§8.14) classifies the segment's ends by the TF and integrates kappa and rho linear in
between in closed form (Gauss-Legendre up to optical depth 1, erfcx or Dawson's integral beyond, float32). Measured
against the CPU reference on llvmpipe (``tests/test_render_gl_pt.py``, 8-bit): three flat surfaces RMSE 0.24 / max
0.49 (camera inside 0.16 / 0.29), smooth 0.17 / 0.50 and 0.22 / 0.50, pre-classified 0.24-0.28 / 0.50: the screen's
rounding.

Timings on llvmpipe (Mesa 22.3, 2 cores shared with other work; Blunt Fin, 3D table; ``volviz bench unstructured``,
docs/bench/pt-gl, one run): 1.11 s per frame at 512^2 (the CPU ``pt`` in the same run: 0.88 s with the 3D table,
1.17 s with the separable one), 3.4 s at 1024^2 (``pt`` 4.3 s) and 4.7 s at 1920x1080 (``pt`` 6.0 s). What the
fragment shader costs there (1920x1080, the same frames with parts of the shader replaced; the machine was shared,
so these varied between runs): the table lookup a fifth to a half of the frame, the ray clipping and the rest of the
arithmetic most of the remainder; rasterising and blending alone (a constant color) 0.8 s. Compiled into the
shader instead of switched or looped on uniforms: the kind of lookup (512^2: 3.7 s per frame with the four kinds
behind a uniform, 1.4 s compiled) and the number of clipping planes (960x540, the shader without its lookup: 1.45 s
with a loop over a uniform count of 0, 0.91 s compiled); a half-float table and an early ``discard`` (llvmpipe masks
lanes and still runs the code after it) did not help. In a 64^2 window the CPU-side cost with a GPU (sort, index
buffer build and upload, one draw submission) is 0.056 s per frame, the whole frame on llvmpipe 0.22 s (its vertex
stage runs on the CPU); vtkProjectedTetrahedraMapper takes 0.54 s there.

Not handled yet: a renderer that does not fill its window (the ray basis, the targets and the depth blit assume the
renderer's size with its origin at the framebuffer's corner: tested with full-window renderers only), depth peeling
for other translucent props of the same renderer (the pass draws them in order). Call ``remove()`` before closing
the plotter.
"""
from __future__ import annotations

import time
from importlib import resources
from typing import Any

import numpy as np

from volviz.model.datasets import TetMesh
from volviz.render.image_overlay import hold_single_sample, release_single_sample, window_size
from volviz.render.pt_view import PTView
from volviz.render.reduced_fill import INTERACTIVE_PIXELS, reduced_size, scaled_rays
from volviz.model.camera import Camera
from volviz.unstructured.iso import iso_visible
from volviz.unstructured.topology import FACES, cell_ranges, topology, visible_cells

__all__ = ["GLPTVolume", "shader_source"]

_PASS_MARK = "_volviz_gl_pt_pass"      # renderer attribute: the framebuffer pass installed on it
_USERS = "_volviz_gl_pt_volumes"       # renderer attribute: the GLPTVolumes drawing in it
_MAX_CLIP = 8                          # clipping planes the fragment shader takes
_LOOKUPS = ("auto", "3d", "separable")
_AMBIENT = 0.3                         # smooth isosurfaces: vertex_shade's default ambient term
_GL_DRAW_FRAMEBUFFER_BINDING, _GL_READ_FRAMEBUFFER, _GL_DRAW_FRAMEBUFFER = 0x8CA6, 0x8CA8, 0x8CA9
_GL_DEPTH_BUFFER_BIT, _GL_COLOR_BUFFER_BIT, _GL_NEAREST, _GL_DEPTH_WRITEMASK = 0x100, 0x4000, 0x2600, 0x0B72
_GL_VIEWPORT = 0x0BA2
_STILL_RATE_MAX = 1.0                  # frames/s: a window's desired update rate above it is an interaction's


def shader_source(name: str) -> str:
    """The text of ``resources/shaders/<name>`` (package ``volviz_resources``), its ``//VOLVIZ::include <file>``
    lines replaced by those files (the pixel ray and opaque depth shared by the ray-segment shaders,
    ``ray_pixel.glsl``)."""
    text = (resources.files("volviz_resources") / "shaders" / name).read_text(encoding="utf-8")
    lines = []
    for line in text.splitlines():
        head, _, rest = line.partition("//VOLVIZ::include ")
        lines.append(shader_source(rest.strip()) if not head.strip() and rest else line)
    return "\n".join(lines) + "\n"


def _cell_attributes(mesh: TetMesh, smooth: bool = False) -> dict[str, np.ndarray]:
    """Per-cell (m, 4) float32 attributes, relative to the mesh centre: the four face planes (n, d) and the scalar
    form (g, c) with s(x) = g . x + c inside the cell (x relative to the centre); the cell's scalar (min, max, 0, 0).
    Zero-volume cells get g = 0 (they hold no medium; their segments have zero length). ``smooth`` adds the x, y and
    z of the normals of the cell's 4 vertices (``volviz.unstructured.iso.vertex_normals``; vertex f opposite face f)
    and 1 / (d_f - n_f . p_f), which turns face f's plane into the barycentric coordinate of vertex f."""
    topo = topology(mesh)
    p = topo.points[topo.tets]                                       # (m, 4, 3)
    s = np.nan_to_num(mesh.scalars[topo.tets].astype(np.float64))    # NaN cells are culled from the order
    edges = p[:, 1:] - p[:, :1]                                      # (m, 3, 3)
    ds = s[:, 1:] - s[:, :1]
    det = np.linalg.det(edges)
    ok = np.abs(det) > 1e-300
    g = np.zeros((len(p), 3))
    g[ok] = np.linalg.solve(edges[ok], ds[ok][..., None])[..., 0]
    c = s[:, 0] - np.einsum("ij,ij->i", g, p[:, 0])
    r = cell_ranges(mesh)
    out = {f"ptPlane{f}": np.concatenate([topo.face_n[:, f], topo.face_d[:, f, None]], axis=1) for f in range(4)}
    out["ptScalar"] = np.concatenate([g, c[:, None]], axis=1)
    out["ptRange"] = np.stack([r.smin, r.smax, np.zeros_like(r.smin), np.zeros_like(r.smin)], axis=1)
    if smooth:
        from volviz.unstructured.iso import vertex_normals

        normals = vertex_normals(mesh)[topo.tets]                     # (m, 4, 3)
        for axis, name in enumerate("XYZ"):
            out[f"ptNormal{name}"] = normals[..., axis]
        height = topo.face_d - np.einsum("mfk,mfk->mf", topo.face_n, p)
        out["ptBary"] = np.divide(1.0, height, out=np.zeros_like(height), where=height > 1e-300)
    return {k: np.ascontiguousarray(v, dtype=np.float32) for k, v in out.items()}


def _polydata(mesh: TetMesh, smooth: bool = False) -> Any:
    """The static vertex buffer as vtkPolyData: 4 points per tetrahedron (relative to the centre) with the cell
    attributes repeated at each, and no cells yet (the order sets them)."""
    from volviz.render.vtk_facade import numpy_to_vtk, vtk

    topo = topology(mesh)
    pd = vtk.vtkPolyData()
    pts = vtk.vtkPoints()
    pts.SetData(numpy_to_vtk(np.ascontiguousarray(topo.points[topo.tets].reshape(-1, 3), np.float32), deep=True))
    pd.SetPoints(pts)
    for name, arr in _cell_attributes(mesh, smooth).items():
        va = numpy_to_vtk(np.ascontiguousarray(np.repeat(arr, 4, axis=0)), deep=True)
        va.SetName(name)
        pd.GetPointData().AddArray(va)
    pd.SetPolys(vtk.vtkCellArray())
    return pd


def _resolve_polydata(bounds: np.ndarray) -> Any:
    """The resolve's geometry: the 8 corners of ``bounds`` (3, 2) in the actor's bounds, so that VTK culls it with
    the cells, and the triangle (0, 1, 2), which ``pt_resolve_vs.glsl`` places over the viewport by ``gl_VertexID``
    (vertex 7 of the bounds' zero-area triangle lands on vertex 0)."""
    from volviz.render.vtk_facade import box_corners_polydata

    return box_corners_polydata(bounds, [(0, 1, 2)])


def _triangles(cells: np.ndarray, offsets: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(offsets, connectivity), int32, of the 4 faces of each cell in ``cells`` (in that order), for
    vtkCellArray.SetData; ``offsets``: 0, 3, 6, ... for at least as many triangles, sliced instead of made. 32-bit
    arrays handed to VTK without a copy: 3 ms for the Blunt Fin's 750,000 triangles, 28 ms with 64-bit copies."""
    conn = ((4 * cells.astype(np.int32))[:, None] + FACES.reshape(1, 12).astype(np.int32)).reshape(-1)
    n = len(conn) // 3 + 1
    if offsets is None or len(offsets) < n:
        offsets = np.arange(0, 3 * n, 3, dtype=np.int32)
    return offsets[:n], conn


def _shader(name: str, smooth: bool, kind: int = 0, clips: int = 0) -> str:
    """A pass shader for one kind of segment evaluation (``PT_KIND``: 0 3D table, 1 separable, 2 isosurfaces, 3
    pre-classified) and ``clips`` user clipping planes (``PT_CLIPS``), with ``PT_SMOOTH`` defined for smooth
    isosurfaces."""
    head = f"#define PT_KIND {kind}\n#define PT_CLIPS {clips}\n" + ("#define PT_SMOOTH\n" if smooth else "")
    return _with_defines(shader_source(name), head)


def _with_defines(source: str, head: str) -> str:
    """``source`` with the ``#define`` lines ``head`` right after VTK's system declarations."""
    return source.replace("//VTK::System::Dec\n", "//VTK::System::Dec\n" + head, 1)


def _resolve_shader(upsample: bool) -> str:
    """The resolve's fragment shader: one texel per pixel, or (``upsample``, an interactive frame drawn smaller) the
    target sampled bilinearly at each pixel's centre (``PT_UPSAMPLE``; compiled in, not switched: llvmpipe would pay
    for both branches, module docstring)."""
    return _with_defines(shader_source("pt_resolve_fs.glsl"), "#define PT_UPSAMPLE\n" if upsample else "")


def install_scene_pass(renderer: Any, user: object) -> None:
    """A float32 color target around VTK's standard render steps (a ``vtkFramebufferPass``, its depth texture
    holding the opaque scene) on ``renderer``, translucent props drawn in order; shared by the GL layers that use it
    (``GLPTVolume``, ``volviz.render.gl_fog.GLFogLayer``); ``user`` is counted as one (the last one to leave takes
    the pass off)."""
    from volviz.render.vtk_facade import vtk

    renderer.SetUseDepthPeeling(False)
    renderer.SetUseOIT(False)
    if getattr(renderer, _PASS_MARK, None) is None:
        fb = vtk.vtkFramebufferPass()
        fb.SetColorFormat(vtk.vtkTextureObject.Float32)
        fb.SetDelegatePass(vtk.vtkRenderStepsPass())
        renderer.SetPass(fb)
        setattr(renderer, _PASS_MARK, fb)
    if getattr(renderer, _USERS, None) is None:
        setattr(renderer, _USERS, [])
    getattr(renderer, _USERS).append(user)


def _order_key(cam: Camera, size: tuple[int, ...]) -> tuple[Any, ...]:
    """What a visibility order depends on: the camera and the image size."""
    return (tuple(cam.position), tuple(cam.focal_point), tuple(cam.view_up), cam.view_angle, cam.parallel,
            cam.parallel_scale, tuple(size))


class GLPTVolume(PTView):
    """A TetMesh drawn by the GPU pre-integrated PT pass in a PyVista plotter's renderer (module docstring).

    ``lookup``: "3d" (default; n_s x n_s x n_l trilinear, ``table_size``), "separable" (degree ``degree``) or
    "auto" (as the CPU ``pt``). ``iso`` (an ``IsoTable``), ``iso_shading`` ("flat" or "smooth") and
    ``classification`` ("post" or "pre") as the CPU ``render(..., iso_mode="exact")``: exact per-segment
    isosurfaces instead of the volume (``tf`` is then ignored and may be None), or pre-classified segments integrated
    in closed form. ``sort``/``nonconvex``: as ``visibility_order``. ``stats`` holds the last new index
    buffer's CPU-side seconds (``sort_s``, ``order_s``), the number of cells drawn, and whether a new order was made
    for the camera (``sorted``: here or by ``prefetch``), taken from ``prefetch`` or reused. ``prefetch(camera)``
    sorts for a known next camera in the background; ``reuse_order = True`` never sorts in a render: it draws the
    newest order it has (e.g. during a mouse drag: the image is then exact per cell but may composite some
    overlapping cells in the wrong order), and ``begin`` / ``compute`` / ``finish`` make the order for the camera of
    ``begin`` on a worker while the GPU draws (the app's background jobs, as for the CPU backend's images; the bench
    states what a reused order costs). ``camera``: the camera of the last draw. ``set_interactive`` /
    ``interactive_pixels``: the reduced-resolution frames while the camera moves (module docstring); ``drawn_size``:
    the size the last frame's cells were drawn at. The GPU side of the PT view interface
    ``volviz.render.pt_view.PTView``: VTK draws it at every render, so ``update`` has nothing to do.
    ``keep_multisampling``: leave the window's multisampling on (module docstring; default off while the volume is
    shown)."""

    backend = "gpu"
    job = ("pt-order", "visibility order")   # the app's key for its updates, and what its worker makes
    follows_camera = True   # during an interaction each frame starts its camera's sort (``_follow``); False: a
    #                         subclass gives the order itself (``gl_nature.CloudPTVolume``: each frame's leaves)

    def __init__(self, plotter: Any, mesh: TetMesh, tf: Any, *, lookup: str = "3d", n_s: int | None = None,
                 n_l: int = 64, degree: int | None = None, sort: str = "mpvo", nonconvex: str = "auto",
                 iso: Any = None, iso_shading: str = "flat", classification: str = "post",
                 keep_multisampling: bool = False) -> None:
        from volviz.render.vtk_facade import premultiplied_texture, vtk

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
        self.iso, self.iso_shading, self.classification = iso, iso_shading, classification
        smooth = iso is not None and iso_shading == "smooth"
        self.plotter = plotter
        self.renderer = plotter.renderer
        self.mesh = self.whole_mesh = mesh           # clipping cuts per fragment: the mesh stays whole
        self.topo = topology(mesh)
        self.lookup, self.n_s, self.n_l, self.degree = lookup, n_s, n_l, degree
        self.sort, self.nonconvex = sort, nonconvex
        self.stats: dict[str, Any] = {"method": "pt-gl"}
        self.camera: Camera | None = None
        self.order: np.ndarray | None = None       # the drawn cells, back to front
        self.reuse_order = False                    # keep the last order whatever the camera (during interaction)
        self._sorted: np.ndarray | None = None      # the last full visibility order (all cells)
        self._sorted_key: Any = None                # the camera and size that order was made for
        self._offsets: np.ndarray | None = None     # 0, 3, 6, ...: the index buffer's triangle offsets
        self._cell_arrays: tuple[np.ndarray, np.ndarray] | None = None   # the arrays VTK's cells share
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
        self._table: Any = None
        self._table_tex: Any = None
        self._targets: tuple[Any, ...] | None = None   # color, its FBO, depth, its FBO, format, drawn-size depth, FBO
        self.interactive: bool | None = None        # None: interactive while the window's update rate says so
        self.interactive_pixels = INTERACTIVE_PIXELS
        self.drawn_size: tuple[int, int] | None = None  # the last frame's cells were drawn at this size
        self._viewport: list[int] | None = None     # the scene's viewport while the cells draw smaller
        self._upsample = False                      # the resolve's shader variant (``_resolve_shader``)
        self._bound = False                         # the volume's color target is bound (cells drawn, no resolve yet)
        self._drawn = False                         # the cells were drawn this frame
        self._table_dirty = True
        self._clip = np.zeros((0, 4))
        self.tf = tf
        self._vis = self._visible()

        self.polydata = _polydata(mesh, smooth)
        self.mapper = vtk.vtkOpenGLPolyDataMapper()
        self.mapper.SetInputData(self.polydata)
        self.mapper.ScalarVisibilityOff()
        sp = vtk.vtkShaderProperty()
        sp.SetVertexShaderCode(_shader("pt_tet_vs.glsl", smooth))
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
        self.resolve_mapper.SetInputData(_resolve_polydata(np.stack([pts.min(axis=0), pts.max(axis=0)], axis=1)))
        rsp = vtk.vtkShaderProperty()
        rsp.SetVertexShaderCode(shader_source("pt_resolve_vs.glsl"))
        rsp.SetFragmentShaderCode(_resolve_shader(False))
        self.resolve_actor = vtk.vtkActor()
        self.resolve_actor.SetMapper(self.resolve_mapper)
        self.resolve_actor.SetShaderProperty(rsp)
        self.resolve_actor.SetPosition(*self.topo.origin)
        self.resolve_actor.ForceTranslucentOn()
        self.resolve_actor.SetTexture(premultiplied_texture())

        self.renderer.SetUseDepthPeeling(False)    # translucent props drawn in order: the cells, then the resolve
        self.renderer.SetUseOIT(False)
        self.keep_multisampling = keep_multisampling
        if not keep_multisampling:
            hold_single_sample(plotter, self)      # one color per pixel, as the CPU backend's overlays
            self._install_pass()                   # the renderer's float32 scene target, as the GL fog layers'
        GLPTVolume._on_program.CallDataType = vtk.VTK_OBJECT     # type: ignore[attr-defined]
        self._observers = [
            (self.mapper, self.mapper.AddObserver(vtk.vtkCommand.UpdateShaderEvent, self._on_program)),
            (self.resolve_mapper, self.resolve_mapper.AddObserver(vtk.vtkCommand.UpdateShaderEvent,
                                                                  self._on_program)),
            (self.renderer, self.renderer.AddObserver(vtk.vtkCommand.StartEvent, self._on_start)),
            (self.renderer, self.renderer.AddObserver(vtk.vtkCommand.EndEvent, self._on_end)),
        ]
        self.renderer.AddActor(self.actor)
        self.renderer.AddActor(self.resolve_actor)

    # --- set-up --------------------------------------------------------------------------------------------------
    def _on_program(self, caller: Any, event: str, program: Any = None) -> None:
        """UpdateShaderEvent of either mapper (its program being bound): the cells' or the resolve's set-up."""
        if program is not None:
            (self._on_update_shader if caller is self.mapper else self._on_resolve)(program)

    def _install_pass(self) -> None:
        """The renderer's shared float32 scene target (``install_scene_pass``), this volume counted as a user.
        GLPTVolume itself draws into its own target (module docstring) and works with or without it."""
        install_scene_pass(self.renderer, self)

    # --- per frame -----------------------------------------------------------------------------------------------
    def _camera(self) -> Camera:
        return Camera.from_pyvista(self.renderer.GetActiveCamera())

    def _on_start(self, *_: Any) -> None:
        """Before each render: the back-to-front index buffer for this camera (unchanged cameras keep theirs; a
        prefetched order for this camera is taken; with ``reuse_order`` the last order is kept for any camera, but
        never one older than the previous frame's camera: ``_follow``)."""
        from volviz.unstructured.sort import visibility_order

        if not self.actor.GetVisibility():
            return
        self._apply_kind()
        size = window_size(self.renderer)
        self.drawn_size = self.draw_size()
        self._apply_upsample(self.drawn_size != size)
        cam = self.camera = self._camera()
        key = _order_key(cam, size)
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
        cells = self._sorted[self._vis[self._sorted]]
        self._set_index_buffer(cells)
        self.order, self._order_key = cells, key
        self.stats = {"method": "pt-gl", "sort_s": t1 - t0, "order_s": time.perf_counter() - t1,
                      "n_visible": int(len(cells)), "cycles": self._cycles, "sorted": res is not None,
                      "sort_prefetched": prefetched, "order_reused": not exact and res is None}
        self._log_frame()

    FRAME_LOG = 1000

    def _log_frame(self) -> None:
        self.frames.append((self.camera_serial, self.order_serial))
        del self.frames[:-self.FRAME_LOG]

    def _follow(self, cam: Camera, size: tuple[int, int]) -> tuple[Any, int, Any]:
        """A frame during an interaction (``reuse_order``), for a camera with no order yet: take the order of the
        sort the previous frame started on the worker (waiting for it: a sort of the Blunt Fin takes ~13 ms, which
        it has had the previous frame's draw to do), and start this camera's. So the drawn order is never older than
        the previous frame's camera, and each camera's order is made on the worker within one frame (issue #29).
        Returns (the order or None, the camera serial and ``_order_key`` it was made for)."""
        from volviz.unstructured.prefetch import SortPrefetcher

        res, serial, made_for = None, self.order_serial, self._sorted_key
        if self._frame_sort is not None and self._frame_sort[0] > self.order_serial:
            p_serial, p_cam, p_size = self._frame_sort
            res = self._prefetcher.take(p_cam, p_size)
            if res is not None:
                serial, made_for = p_serial, _order_key(p_cam, p_size)
        if self._prefetcher is None:
            self._prefetcher = SortPrefetcher(self.mesh, sort=self.sort, nonconvex=self.nonconvex)
        self._prefetcher.prefetch(cam, size)
        self._frame_sort = (self.camera_serial, cam, size)
        return res, serial, made_for

    def begin(self, scale: int = 1) -> dict[str, Any]:
        """GUI thread: the order to make next, for the renderer's camera and size now (``scale`` > 1: asked for
        during an interaction; the order is the same). A caller that makes the orders on a worker from now on
        (``compute``) keeps them off the GUI thread: renders reuse the newest order (``reuse_order``)."""
        self.reuse_order = True
        cam = self._camera()
        size = window_size(self.renderer)
        key = _order_key(cam, size)
        serial = self.camera_serial + (key != self._frame_key)   # a camera not drawn yet: the next frame's
        return {"camera": cam, "size": size, "key": key, "topo": self.topo, "preview": scale > 1, "serial": serial,
                "have": self._sorted is not None and key == self._sorted_key, "prefetcher": self._prefetcher}

    def compute(self, request: dict[str, Any], progress: Any = None) -> tuple[Any]:
        """Any thread: the visibility order for ``begin``'s camera (``volviz.unstructured.sort``); None when the
        volume has it already (e.g. a transfer-function edit asked for a new image)."""
        from volviz.unstructured.sort import visibility_order

        if request["have"]:
            return (None,)
        pre = request.get("prefetcher")
        res = None if pre is None else pre.take(request["camera"], request["size"], consume=False)
        if res is not None:        # a frame of a drag started this camera's sort (``_follow``): no second sort
            return (res,)
        return (visibility_order(request["topo"], request["camera"], request["size"], self.sort, self.nonconvex),)

    def finish(self, request: dict[str, Any], result: Any) -> None:
        """GUI thread: draw with ``compute``'s order from the next render on: exact for its camera, and with
        ``reuse_order`` the newest order for any other (during an interaction the camera has moved on meanwhile)."""
        if result is None or request["topo"] is not self.topo or request.get("serial", 0) < self.order_serial:
            return                 # none, of another mesh, or older than the order drawn now
        self._sorted, self._cycles, self._sorted_key = result.order, int(result.cycles), request["key"]
        self.order_serial = request.get("serial", self.order_serial)
        self._recull = True

    def _set_index_buffer(self, cells: np.ndarray) -> None:
        """Draw ``cells`` back to front (4 triangles each) from the next render on: the polydata's cells are 32-bit
        numpy arrays shared with VTK (kept referenced here), VTK builds and uploads the index buffer from them."""
        from volviz.render.vtk_facade import numpy_to_vtk

        if self.topo.n_tets * 4 >= 2 ** 31:
            raise ValueError("too many tetrahedra for 32-bit vertex indices")
        offsets, conn = _triangles(cells, self._offsets)
        self._offsets = offsets.base if offsets.base is not None else offsets
        self._cell_arrays = (offsets, conn)
        self.polydata.GetPolys().SetData(numpy_to_vtk(offsets, deep=False), numpy_to_vtk(conn, deep=False))
        self.polydata.Modified()

    def prefetch(self, camera: Camera, size: tuple[int, int] | None = None) -> None:
        """Sort for ``camera`` (the next frame's; ``size`` defaults to the renderer's) on a background worker, so
        that the render for that camera skips the sort (``volviz.unstructured.prefetch``; another camera sorts as
        usual)."""
        from volviz.unstructured.prefetch import SortPrefetcher

        if self._prefetcher is None:
            self._prefetcher = SortPrefetcher(self.mesh, sort=self.sort, nonconvex=self.nonconvex)
        if size is None:
            size = window_size(self.renderer)
        self._prefetcher.prefetch(camera, size)

    def _on_end(self, *_: Any) -> None:
        self._restore()                            # only if the resolve did not draw
        self._drawn = False
        if self._table_tex is not None:
            self._table_tex.Deactivate()
        t = self._targets
        for tex in (t[0], t[2], t[5]) if t is not None else ():   # the color and the depth textures
            if tex is not None:
                tex.Deactivate()

    def _make_targets(self, size: tuple[int, int], drawn: tuple[int, int], depth_format: int) -> tuple[Any, ...]:
        """The volume's float32 RGBA target of the ``drawn`` size (linear filtering, for the upsampling resolve),
        its copy of the opaque depth at the window's ``size`` (``depth_format``: the scene's depth attachment's, as a
        depth blit needs) and, when ``drawn`` is smaller, that depth again at the ``drawn`` size (else None), each
        attached to a framebuffer object of its own (made again when a size changes)."""
        from volviz.render.vtk_facade import vtk

        t = self._targets
        if (t is not None and (t[0].GetWidth(), t[0].GetHeight()) == drawn
                and (t[2].GetWidth(), t[2].GetHeight()) == size and t[4] == depth_format):
            return t
        self._release_targets()
        ren_win = self.renderer.GetRenderWindow()

        def target(w: int, h: int, depth: bool) -> tuple[Any, Any]:
            tex = vtk.vtkTextureObject()
            tex.SetContext(ren_win)
            fbo = vtk.vtkOpenGLFramebufferObject()
            fbo.SetContext(ren_win)
            fbo.SaveCurrentBindingsAndBuffers()
            fbo.Bind()
            if depth:                                                  # read by texelFetch: no filtering
                tex.AllocateDepth(w, h, depth_format)
                fbo.AddDepthAttachment(tex)
            else:
                tex.Create2D(w, h, 4, vtk.VTK_FLOAT, False)
                tex.SetMinificationFilter(vtk.vtkTextureObject.Linear)
                tex.SetMagnificationFilter(vtk.vtkTextureObject.Linear)
                tex.SetWrapS(vtk.vtkTextureObject.ClampToEdge)
                tex.SetWrapT(vtk.vtkTextureObject.ClampToEdge)
                fbo.AddColorAttachment(0, tex)
            fbo.RestorePreviousBindingsAndBuffers()
            return tex, fbo

        small = target(*drawn, True) if drawn != size else (None, None)
        self._targets = (*target(*drawn, False), *target(*size, True), depth_format, *small)
        return self._targets

    def _release_targets(self) -> None:
        ren_win = self.renderer.GetRenderWindow()
        if self._targets is not None and ren_win is not None:
            for obj in self._targets[:4] + self._targets[5:]:
                if obj is not None:
                    obj.ReleaseGraphicsResources(ren_win)
        self._targets = None

    def _bind_target(self, size: tuple[int, int], drawn: tuple[int, int]) -> Any:
        """Copy the scene's depth at this point of the frame (after the opaque pass: the opaque geometry's; one sample
        of each pixel when the window is multisampled) into the volume's depth texture (then, for a frame drawn
        smaller, the nearest sample of it into the ``drawn``-size one), then bind and clear the volume's color target
        for the cells (and set the viewport to ``drawn``). Returns the depth texture the cells read."""
        from volviz.render.vtk_facade import vtk

        ren_win = self.renderer.GetRenderWindow()
        state = ren_win.GetState()
        scene = [0]
        state.vtkglGetIntegerv(_GL_DRAW_FRAMEBUFFER_BINDING, scene)
        color, color_fbo, depth, depth_fbo, _, small, small_fbo = self._make_targets(
            size, drawn, self._scene_depth_format(scene[0]))
        color_fbo.SaveCurrentBindingsAndBuffers()
        self._bound = True
        w, h = size
        mask = [1]
        state.vtkglGetBooleanv(_GL_DEPTH_WRITEMASK, mask)
        state.vtkglDepthMask(True)                  # a depth blit writes through the depth write mask
        state.vtkglBindFramebuffer(_GL_READ_FRAMEBUFFER, scene[0])
        state.vtkglBindFramebuffer(_GL_DRAW_FRAMEBUFFER, depth_fbo.GetFBOIndex())
        vtk.vtkOpenGLFramebufferObject.Blit((0, w, 0, h), (0, w, 0, h), _GL_DEPTH_BUFFER_BIT, _GL_NEAREST)
        if small is not None:                       # single-sampled to single-sampled: a scaling blit is allowed
            state.vtkglBindFramebuffer(_GL_READ_FRAMEBUFFER, depth_fbo.GetFBOIndex())
            state.vtkglBindFramebuffer(_GL_DRAW_FRAMEBUFFER, small_fbo.GetFBOIndex())
            vtk.vtkOpenGLFramebufferObject.Blit((0, w, 0, h), (0, drawn[0], 0, drawn[1]), _GL_DEPTH_BUFFER_BIT,
                                                _GL_NEAREST)
            depth = small
        state.vtkglDepthMask(bool(mask[0]))
        color_fbo.Bind()
        color_fbo.ActivateDrawBuffer(0)
        state.vtkglClearColor(0.0, 0.0, 0.0, 0.0)
        state.vtkglClear(_GL_COLOR_BUFFER_BIT)
        if drawn != size:
            self._viewport = [0, 0, 0, 0]
            state.vtkglGetIntegerv(_GL_VIEWPORT, self._viewport)
            state.vtkglViewport(0, 0, drawn[0], drawn[1])
        return depth

    def _scene_depth_format(self, fbo_index: int) -> int:
        """The vtkTextureObject depth format matching the depth attachment of the framebuffer being drawn (the window's
        render framebuffer or a render pass's): GL blits depth only between equal formats."""
        from volviz.render.vtk_facade import vtk

        fb = getattr(self.renderer, _PASS_MARK, None)
        if fb is not None:
            tex = fb.GetDepthTexture()
        else:
            tex = self.renderer.GetRenderWindow().GetRenderFramebuffer().GetDepthAttachmentAsTextureObject()
        internal = tex.GetInternalFormat(vtk.VTK_FLOAT, 1, False) if tex is not None else 0
        return {0x81A5: vtk.vtkTextureObject.Fixed16, 0x81A6: vtk.vtkTextureObject.Fixed24,
                0x81A7: vtk.vtkTextureObject.Fixed32, 0x8CAC: vtk.vtkTextureObject.Float32}.get(
                    internal, vtk.vtkTextureObject.Fixed32)

    def _restore(self) -> None:
        """The scene's framebuffer (and viewport) again."""
        if self._bound:
            assert self._targets is not None  # bound to them
            self._targets[1].RestorePreviousBindingsAndBuffers()
            self._bound = False
        if self._viewport is not None:
            self.renderer.GetRenderWindow().GetState().vtkglViewport(*self._viewport)
            self._viewport = None

    def _on_resolve(self, program: Any) -> None:
        """The resolve's draw: back to the scene's framebuffer; the volume's image goes over it."""
        self._restore()
        color = self._targets[0] if self._targets is not None else None
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
        from volviz.unstructured.render import auto_lookup

        if self.lookup != "auto":
            return self.lookup, self.degree
        lookup, auto_degree = auto_lookup(self.tf.max_extinction * max(self.topo.max_edge, 1e-12))
        return lookup, self.degree or auto_degree

    def _apply_kind(self) -> None:
        """The fragment shader made for this volume's segment evaluation and number of clipping planes (recompiled by
        VTK when either changes, e.g. an "auto" lookup switching tables with the TF, or a new clipping plane)."""
        if self.iso is not None:
            kind = 2
        elif self.classification == "pre":
            kind = 3
        else:
            kind = 0 if self._resolved_lookup()[0] == "3d" else 1
        if (kind, len(self._clip)) != self._kind:
            self._kind = (kind, len(self._clip))
            self.actor.GetShaderProperty().SetFragmentShaderCode(
                _shader("pt_tet_fs.glsl", self.iso is not None and self.iso_shading == "smooth", *self._kind))

    def _build_table(self) -> Any:
        from volviz.unstructured.render import Preclassified, _table_for, table_size

        if self.iso is not None:
            return self.iso
        if self.classification == "pre":
            return Preclassified(self.tf)
        tf, topo = self.tf, self.topo
        l_max = max(topo.max_edge, 1e-12)
        lookup, degree = self._resolved_lookup()
        if lookup == "3d":
            return _table_for(self.mesh, tf, "3d", table_size(tf.max_extinction * l_max, self.n_s or 128, self.n_l),
                              l_max)
        return _table_for(self.mesh, tf, "separable", (self.n_s or 256, int(degree or 2)), l_max)

    def _upload_table(self, ren_win: Any) -> None:
        from volviz.render.vtk_facade import vtk

        table = self._table
        if hasattr(table, "isosurfaces"):                            # rows of texels: value, opacity; colors
            isos = sorted(table.isosurfaces, key=lambda i: i.value)
            data = np.zeros((1, 3, len(isos), 4), np.float32)
            for k, i in enumerate(isos):
                data[0, :, k, :3] = [(i.value, i.opacity, 0.0), i.color,
                                     i.color if i.back_color is None else i.back_color]
            nx, ny, nz = len(isos), 3, 1
        elif hasattr(table, "preclassified_tf"):                     # rows of texels: (kappa, rho); scalar
            tf = table.preclassified_tf
            data = np.zeros((1, 2, len(tf.scalars), 4), np.float32)
            data[0, 0, :, :3] = tf.colors
            data[0, 0, :, 3] = tf.extinction
            data[0, 1, :, 0] = tf.scalars
            nx, ny, nz = len(tf.scalars), 2, 1
        elif hasattr(table, "rgba"):                                 # 3D: x = l, y = s_b, z = s_f
            data = np.ascontiguousarray(table.rgba, dtype=np.float32)
            nx, ny, nz = data.shape[2], data.shape[1], data.shape[0]
        else:                                                       # separable: x = s_f, y = s_b, layers
            n, deg = table.n_s, table.degree
            layers = np.zeros((deg + 1, n, n, 4), np.float32)
            d = table.data.transpose(1, 0, 2)                       # (s_b, s_f, channels)
            layers[0] = d[..., 0:4]
            for i in range(1, deg + 1):
                layers[i, ..., :3] = d[..., 1 + 3 * i:4 + 3 * i]
            data = np.ascontiguousarray(layers)
            nx, ny, nz = n, n, deg + 1
        if self._table_tex is not None:
            self._table_tex.ReleaseGraphicsResources(ren_win)
        tex = vtk.vtkTextureObject()
        tex.SetContext(ren_win)
        if hasattr(table, "kappa_max"):          # separable: a 2D array, bilinear within each layer (4 taps, not 8)
            tex.Create2DArrayFromRaw(nx, ny, 4, vtk.VTK_FLOAT, nz, data)
        else:
            tex.Create3DFromRaw(nx, ny, nz, 4, vtk.VTK_FLOAT, data)
        tex.SetMinificationFilter(vtk.vtkTextureObject.Linear)
        tex.SetMagnificationFilter(vtk.vtkTextureObject.Linear)
        tex.SetWrapS(vtk.vtkTextureObject.ClampToEdge)
        tex.SetWrapT(vtk.vtkTextureObject.ClampToEdge)
        tex.SetWrapR(vtk.vtkTextureObject.ClampToEdge)
        self._table_tex = tex
        self._table_dirty = False

    def _on_update_shader(self, program: Any) -> None:
        """Uniforms and textures for the draw (set as the mapper's program is bound)."""
        if program is None:
            return
        ren_win = self.renderer.GetRenderWindow()
        if self._table is None or self._table_dirty:
            self._table = self._build_table()
            self._upload_table(ren_win)
        cam = self._camera()
        size = window_size(self.renderer)
        drawn = self.drawn_size or size
        rb = cam.rays(size, origin=self.topo.origin)
        if drawn != size:                          # an interactive frame: the same view's rays at fewer pixels
            rb = scaled_rays(rb, size, drawn)
        for name, v in (("rayO0", rb.o0), ("rayOx", rb.ox), ("rayOy", rb.oy), ("rayD0", rb.d0), ("rayDx", rb.dx),
                        ("rayDy", rb.dy)):
            program.SetUniform3f(name, [float(x) for x in v])
        program.SetUniformf("viewHeight", float(drawn[1]))
        program.SetUniform2f("clipRange", [float(x) for x in cam.clipping_range])
        program.SetUniformi("parallelView", int(cam.parallel))
        if len(self._clip):
            program.SetUniform4fv("clipPlanes", len(self._clip), [float(x) for x in self._clip.ravel()])
        depth = self._bind_target(size, drawn)     # the opaque scene's depth, the volume's own color target
        depth.Activate()
        self._drawn = True
        program.SetUniformi("useDepth", 1)
        program.SetUniformi("opaqueDepth", depth.GetTextureUnit())
        table = self._table
        self._table_tex.Activate()
        program.SetUniformi("ptTable", self._table_tex.GetTextureUnit())
        if hasattr(table, "isosurfaces"):
            program.SetUniformi("rowCount", len(table.isosurfaces))
            program.SetUniformf("isoThicken", float(table.thicken))
            if self.iso_shading == "smooth":
                program.SetUniform3f("shadeLight", [float(x) for x in cam.frame()[2]])
                program.SetUniformf("shadeAmbient", _AMBIENT)
            return
        if hasattr(table, "preclassified_tf"):
            program.SetUniformi("rowCount", len(table.preclassified_tf.scalars))
            return
        program.SetUniform4f("tableAxis", [float(table.s_lo), float(1.0 / table.ds), float(table.n_s), 0.0])
        if hasattr(table, "rgba"):
            program.SetUniform4f("tableLength", [float(1.0 / table.dl), float(table.n_l), 0.0, 0.0])
        else:
            program.SetUniform4f("tableLength", [float(1.0 / table.l_max), 0.0, float(table.degree), 0.0])
            program.SetUniform3f("kappaMax", [float(x) for x in table.kappa_max])

    def _apply_upsample(self, on: bool) -> None:
        """The resolve's shader variant for this frame (VTK keeps both programs compiled once made)."""
        if on != self._upsample:
            self._upsample = on
            self.resolve_actor.GetShaderProperty().SetFragmentShaderCode(_resolve_shader(on))

    # --- public --------------------------------------------------------------------------------------------------
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
        if self._targets is None:
            return None
        return int(self._targets[0].GetWidth()), int(self._targets[0].GetHeight())

    def _use_tf(self, tf: Any) -> None:
        """A new transfer function (``set_tf``): the table texture is rebuilt at the next render and the
        zero-opacity culling follows it (a new index buffer from the same visibility order: the sort does not depend
        on the TF; the vertex buffer stays)."""
        self.tf = tf
        self._vis = self._visible()
        self._table_dirty = True
        self._recull = True

    def set_clip_planes(self, planes: Any = (), box: Any = None) -> None:
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

    def set_clip(self, clip: Any) -> bool:
        """Clip by ``volviz.model.clip.ClipSettings`` (its planes and box) per fragment (``set_clip_planes``); returns
        True (``PTView.set_clip``: nothing for the caller to cut)."""
        self.set_clip_planes([(p.normal, p.point) for p in clip.all_planes()])
        return True

    def update(self) -> None:
        """Nothing to re-make: the next render sorts for its camera and draws (``PTView.update``)."""

    @property
    def visible(self) -> bool:
        return bool(self.actor.GetVisibility())

    @visible.setter
    def visible(self, on: bool) -> None:
        self.actor.SetVisibility(bool(on))
        self.resolve_actor.SetVisibility(bool(on))

    def remove(self) -> None:
        """Take the volume out of the renderer; the last GL PT volume of a renderer removes the float target (call
        it before closing the plotter: VTK complains when a framebuffer pass outlives its context's resources)."""
        if self._prefetcher is not None:
            self._prefetcher.close()
            self._prefetcher = None
        for obj, tag in self._observers:
            obj.RemoveObserver(tag)
        self._observers = []
        self.renderer.RemoveActor(self.actor)
        self.renderer.RemoveActor(self.resolve_actor)
        ren_win = self.renderer.GetRenderWindow()
        if self._table_tex is not None and ren_win is not None:
            self._table_tex.ReleaseGraphicsResources(ren_win)
        self._table_tex = None
        self._release_targets()
        if not self.keep_multisampling:
            release_single_sample(self.plotter, self)
        users = getattr(self.renderer, _USERS, [])
        if self in users:
            users.remove(self)
        if not users and getattr(self.renderer, _PASS_MARK, None) is not None:
            if ren_win is not None:
                getattr(self.renderer, _PASS_MARK).ReleaseGraphicsResources(ren_win)
            self.renderer.SetPass(None)
            setattr(self.renderer, _PASS_MARK, None)
