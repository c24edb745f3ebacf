"""Which renderer draws a view: the GPU path through VTK's OpenGL or volviz's CPU path, chosen from the render setting
``backend`` ("auto", "gpu", "cpu") and the OpenGL driver a render window runs on.

View kinds with both paths:

- ``"pt"``: unstructured (tetrahedral) volumes by pre-integrated projected tetrahedra (Roettger Ch. 8-9): the GPU
  pass ``volviz.render.gl_pt.GLPTVolume`` (VTK draws it at every render) or the CPU ``volviz.render.pt_prop.PTVolume``
  (an image made by ``volviz.unstructured.render`` off the GUI thread and pasted over VTK's scene).
- ``"regular"``: regular volumes by VTK's ray casters: ``vtkSmartVolumeMapper``'s GPU ray caster or its CPU one.

``auto`` takes the GPU path on a hardware OpenGL driver. On a software rasteriser (Mesa llvmpipe, softpipe, swrast,
Google SwiftShader) the GPU's work runs on the same CPU cores, so ``auto`` takes the path that was faster there (the
figures: ``docs/bench/pt-gl/unstructured.md``, ``docs/bench/iso.md``, docs/bench/docstring-figures.md):

- PT: the CPU ``pt``, faster at every window size on the Blunt Fin. In the app it also renders off the GUI thread
  and draws half-size previews while the camera moves, where the GL pass blocks the GUI thread for a full-size
  draw.
- ``"nature"``: the natural scene's fog and cloud layers and C-LOD clouds: ``volviz.render.gl_nature.GLNatureView``
  (GL prisms and GL PT in the scene's depth buffer) or the CPU ``volviz.render.nature_view.NatureView`` (an overlay
  made off the GUI thread). Auto takes the CPU on a software rasteriser, faster on the demo scene: a software
  rasteriser runs the prisms' and tetrahedra's geometry shaders on the CPU cores, nearly all of the GL path's
  frame.
- ``"iso"``: the isosurfaces' transparency modes of the libMini note §4 (2-pass, 3-pass, 4-pass, exact):
  ``volviz.render.gl_iso.GLIsoView`` (the passes as VTK actors, drawn at every render) or the CPU
  ``volviz.render.iso_overlay.IsoOverlay`` (fragment lists composited off the GUI thread, pasted over the scene).
  Auto takes the GPU on a software rasteriser too: it is faster in every mode on every scene of ``docs/bench/iso.md``,
  the GPU's time including the read-back of the frame.
- regular: VTK's CPU ray caster, faster on the embryo, and in the app it blocks the event loop for less at load and
  per playback frame.

    info = gl_info(plotter.ren_win)              # GLInfo(vendor, renderer, version)
    choose_backend("auto", "pt", info)           # "cpu" on llvmpipe, "gpu" on a hardware driver
    choose_backend("auto", "iso", info)          # "gpu" on both
"""
from __future__ import annotations

import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Mapping, TypedDict

from volviz.session import RENDER_BACKENDS

if TYPE_CHECKING:   # type-only imports for the signatures
    import pyvista as pv
    from volviz.render.vtk_facade import vtkRenderWindow

__all__ = ["RENDER_BACKENDS", "VIEW_KINDS", "GLInfo", "backend_setting", "choose_backend", "gl_info",
           "gpu_in_thread", "is_software_renderer", "offscreen_gl_info", "parse_capabilities", "plotter_gl_info"]

VIEW_KINDS = ("pt", "regular", "nature", "iso")
SOFTWARE_RENDERERS = ("llvmpipe", "softpipe", "swrast", "swiftshader", "software rasterizer")
_FASTER_ON_SOFTWARE = {"pt": "cpu", "regular": "cpu", "nature": "cpu", "iso": "gpu"}     # measured (module docstring)


class GLInfoDict(TypedDict):
    """``GLInfo.to_dict``: the driver's strings and whether it is a software rasteriser (for the bench reports)."""

    vendor: str
    renderer: str
    version: str
    software: bool


@dataclass(frozen=True)
class GLInfo:
    """The OpenGL driver of a render window, as ``glGetString`` reports it ("" where unknown)."""

    vendor: str = ""
    renderer: str = ""
    version: str = ""

    @property
    def software(self) -> bool:
        return is_software_renderer(self.renderer)

    def to_dict(self) -> GLInfoDict:
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
    whole scene once more before the first image; docs/bench/docstring-figures.md);
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
        return gl_info(plotter.ren_win)  # type: ignore[arg-type]  # None once closed; just made
    finally:
        plotter.close()


def backend_setting(options: Mapping[str, object]) -> str:
    """The render option ``backend`` ("auto" when missing)."""
    value = options.get("backend", "auto")
    return value if isinstance(value, str) and value in RENDER_BACKENDS else "auto"


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


def gpu_in_thread(options: Mapping[str, object], info: GLInfo) -> bool:
    """Whether the app draws its GPU PT volumes in a window of a thread of their own (``volviz.render.vtk_pt_image``,
    shown over the scene as an image) instead of in the scene's window: the render option ``gpu_thread`` "on" or
    "off", or "auto" (the default): on a software rasteriser, whose raster of a still frame is CPU work that would
    hold the GUI thread (issue #28)."""
    setting = options.get("gpu_thread", "auto")
    return setting == "on" or (setting not in ("on", "off") and info.software)
