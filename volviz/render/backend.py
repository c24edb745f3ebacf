"""Which renderer draws a view: the GPU path through VTK's OpenGL or volviz's CPU path, chosen from the render setting
``backend`` ("auto", "gpu", "cpu") and the OpenGL driver a render window runs on.

View kinds with both paths:

- ``"pt"``: unstructured (tetrahedral) volumes by pre-integrated projected tetrahedra (Roettger Ch. 8-9): the GPU
  pass ``volviz.render.gl_pt.GLPTVolume`` (VTK draws it at every render) or the CPU ``volviz.render.pt_prop.PTVolume``
  (an image made by ``volviz.unstructured.render`` off the GUI thread and pasted over VTK's scene).
- ``"regular"``: regular volumes by VTK's ray casters: ``vtkSmartVolumeMapper``'s GPU ray caster or its CPU one.

``auto`` takes the GPU path on a hardware OpenGL driver. On a software rasteriser (Mesa llvmpipe, softpipe, swrast,
Google SwiftShader) the GPU's work runs on the same CPU cores, so ``auto`` takes the path measured faster there:

- PT: the CPU ``pt``. ``docs/bench/pt-gl/unstructured.md`` (Blunt Fin, 187,318 tetrahedra, llvmpipe, 2 cores) has
  0.37 s / 0.67 s per frame (CPU ``pt`` / GL PT) at 256², 1.09 / 1.69 s at 512², 2.6 / 5.2 s at 1024² and 6.1 / 6.2 s
  at 1920x1080: the CPU path is faster at every size measured. In the app it also renders off the GUI thread and
  draws half-size previews while the camera moves, where the GL pass blocks the GUI thread for a full-size draw.
- ``"nature"``: the natural scene's fog and cloud layers and C-LOD clouds: ``volviz.render.gl_nature.GLNatureView``
  (GL prisms and GL PT in the scene's depth buffer) or the CPU ``volviz.render.nature_view.NatureView`` (an overlay
  made off the GUI thread). Auto takes the CPU on a software rasteriser: the demo scene on llvmpipe (2 shared cores,
  ~25k cloud tetrahedra, ~60k fog prisms, median of 5 frames) takes 0.18 s per frame on the CPU against 0.22 s on
  the GL path at 512x384 (0.01 s of it LOD selection and handing the buffers to VTK, the rest llvmpipe's draw) and
  0.04 / 0.13 s at 64x48 (llvmpipe runs the prisms' and tetrahedra's geometry shaders on the CPU cores).
- ``"iso"``: the isosurfaces' transparency modes of the libMini note §4 (2-pass, 3-pass, 4-pass, exact):
  ``volviz.render.gl_iso.GLIsoView`` (the passes as VTK actors, drawn at every render) or the CPU
  ``volviz.render.iso_overlay.IsoOverlay`` (fragment lists composited off the GUI thread, pasted over the scene).
  Auto takes the GPU on a software rasteriser too: ``docs/bench/iso.md`` (384², llvmpipe, 2 shared cores; the Storm,
  two overlapping Storm volumes and the Blunt Fin) has 10-13 / 61-107 ms per frame (GPU / CPU) for 2-pass, 20-36 /
  83-165 ms for 3-pass, 37-45 / 106-150 ms for 4-pass and 85-124 / 102-149 ms for exact: the GPU is faster in every
  mode on every scene, the GPU's time including the read-back of the frame.
- regular: VTK's CPU ray caster (measured on 2 cores: the embryo 256³ at 512² takes 0.07 s against 0.26 s with the
  GPU ray caster on llvmpipe; in the app, loading the embryo blocked the event loop 4.3 s with the GPU mapper and 1.2 s
  with the CPU one, and a Storm playback frame took 450 ms against 230 ms).

    info = gl_info(plotter.ren_win)              # GLInfo(vendor, renderer, version)
    choose_backend("auto", "pt", info)           # "cpu" on llvmpipe, "gpu" on a hardware driver
    choose_backend("auto", "iso", info)          # "gpu" on both
"""
from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

from volviz.session import RENDER_BACKENDS

if TYPE_CHECKING:   # type-only imports for the signatures
    import pyvista as pv
    from volviz.render.vtk_facade import vtkRenderWindow

__all__ = ["RENDER_BACKENDS", "VIEW_KINDS", "GLInfo", "backend_setting", "choose_backend", "gl_info",
           "is_software_renderer", "offscreen_gl_info", "parse_capabilities", "plotter_gl_info"]

VIEW_KINDS = ("pt", "regular", "nature", "iso")
SOFTWARE_RENDERERS = ("llvmpipe", "softpipe", "swrast", "swiftshader", "software rasterizer")
_FASTER_ON_SOFTWARE = {"pt": "cpu", "regular": "cpu", "nature": "cpu", "iso": "gpu"}     # measured (module docstring)


@dataclass(frozen=True)
class GLInfo:
    """The OpenGL driver of a render window, as ``glGetString`` reports it ("" where unknown)."""

    vendor: str = ""
    renderer: str = ""
    version: str = ""

    @property
    def software(self) -> bool:
        return is_software_renderer(self.renderer)

    def to_dict(self) -> dict[str, Any]:
        return {"vendor": self.vendor, "renderer": self.renderer, "version": self.version, "software": self.software}


def is_software_renderer(renderer: str) -> bool:
    """Whether an OpenGL renderer string names a software rasteriser (llvmpipe, softpipe, swrast, SwiftShader)."""
    text = renderer.lower()
    return any(name in text for name in SOFTWARE_RENDERERS)


def parse_capabilities(text: str) -> GLInfo:
    """The vendor, renderer and version lines of ``vtkOpenGLRenderWindow.ReportCapabilities()``."""
    found = {}
    for line in text.splitlines():
        for key in ("vendor", "renderer", "version"):
            prefix = f"OpenGL {key} string:"
            if line.startswith(prefix):
                found[key] = line[len(prefix):].strip()
    return GLInfo(**found)


def gl_info(render_window: vtkRenderWindow) -> GLInfo:
    """The OpenGL driver of a VTK render window. One without a context yet gets one: an offscreen window by
    ``Initialize()``, which makes the context without drawing the scene (issue #30: the render it replaces drew the
    whole scene once more before the first image, 0.47 s of CPU for a 1024x768 sphere on llvmpipe against 0.01 s);
    an on-screen one, whose context its toolkit makes, by one render."""
    text = render_window.ReportCapabilities()
    if "renderer string" not in text and render_window.GetOffScreenRendering():
        render_window.Initialize()
        text = render_window.ReportCapabilities()
    if "renderer string" not in text:
        render_window.Render()
        text = render_window.ReportCapabilities()
    return parse_capabilities(text)


_plotter_gl_info: weakref.WeakKeyDictionary[Any, GLInfo] = weakref.WeakKeyDictionary()   # by plotter, once asked


def plotter_gl_info(plotter: pv.BasePlotter) -> GLInfo:
    """``gl_info`` of a PyVista plotter's render window, asked once per plotter."""
    known = _plotter_gl_info.get(plotter)
    if known is None:
        known = _plotter_gl_info[plotter] = gl_info(plotter.ren_win)  # type: ignore[arg-type]  # None once closed
    return known


def offscreen_gl_info() -> GLInfo:
    """The OpenGL driver of VTK's offscreen render windows on this machine (a tiny one, made and closed here)."""
    # heavy: PyVista and VTK (an offscreen plotter), loaded only when the driver is asked about
    from volviz.render.offscreen import offscreen_plotter

    plotter = offscreen_plotter((8, 8))
    try:
        return gl_info(plotter.ren_win)
    finally:
        plotter.close()


def backend_setting(options: dict[str, Any]) -> str:
    """The render option ``backend`` ("auto" when missing)."""
    value = options.get("backend", "auto")
    return value if value in RENDER_BACKENDS else "auto"


def choose_backend(setting: str, view_kind: str, info: GLInfo) -> str:
    """"gpu" or "cpu" for a view of ``view_kind`` (``VIEW_KINDS``) under the render setting ``setting``
    (``RENDER_BACKENDS``): an explicit "gpu" or "cpu" is honoured; "auto" is "gpu" on a hardware driver and the path
    measured faster on a software rasteriser (module docstring)."""
    if setting not in RENDER_BACKENDS:
        raise ValueError(f"unknown backend {setting!r}; choose one of {', '.join(RENDER_BACKENDS)}")
    if view_kind not in VIEW_KINDS:
        raise ValueError(f"unknown view kind {view_kind!r}; choose one of {', '.join(VIEW_KINDS)}")
    if setting != "auto":
        return setting
    return _FASTER_ON_SOFTWARE[view_kind] if info.software else "gpu"
