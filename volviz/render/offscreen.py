"""An offscreen PyVista plotter of a given size: what export, the benches and the OpenGL probe of
``volviz.render.backend`` render into (EGL or OSMesa without a display, llvmpipe on a machine without a GPU)."""
from __future__ import annotations

import os
from typing import TYPE_CHECKING, Protocol, cast

import pyvista as pv

from volviz.render.vtk_facade import vtk

if TYPE_CHECKING:   # type-only: VTK's classes, named by the protocol
    from volviz.render.vtk_facade import vtkRenderer, vtkRenderWindow, vtkVolume


class OpenPlotter(Protocol):
    """A plotter with an open render window, what ``draw_projected_tetrahedra_once`` reads (PyVista types
    ``render_window`` Optional, None once the plotter is closed)."""

    @property
    def renderer(self) -> vtkRenderer: ...

    @property
    def render_window(self) -> vtkRenderWindow: ...


def offscreen_plotter(size: tuple[int, int]) -> pv.Plotter:
    """A ``pyvista.Plotter`` that renders off screen at ``size`` (width, height) pixels."""
    if not os.environ.get("DISPLAY"):  # VTK tries X first and warns before it falls back to EGL: not the user's concern
        vtk.vtkLogger.SetStderrVerbosity(vtk.vtkLogger.VERBOSITY_ERROR)
    skip_display_probe()
    return pv.Plotter(off_screen=True, window_size=[int(size[0]), int(size[1])])


def skip_display_probe() -> None:
    """No probe for an X server before an offscreen plotter: pyvista's ``Plotter`` asks once per process whether
    on-screen plotting works (``_warn_xserver``: a ``xset -q`` subprocess, and where xset is missing a throwaway
    OpenGL context) only to warn that an on-screen window would fail, which an offscreen plotter never opens (issue
    #30, time to the first image: 0.045 s of CPU of each ``volviz render``). The answer is kept where pyvista keeps
    its own; a process that already asked keeps it."""
    # heavy: pyvista's plotting (and matplotlib's colours with it), not loaded until a plotter is made: an error
    # class of this package caught by the CLI must not need matplotlib (a bench without it is a usage error)
    from pyvista.plotting import plotter as pyvista_plotter

    probe = getattr(pyvista_plotter, "_warn_xserver", None)
    if probe is not None and not hasattr(probe, "has_support"):
        probe.has_support = True


def draw_projected_tetrahedra_once(plotter: OpenPlotter) -> None:
    """Before an offscreen plotter's first image: draw its scene once at 8 x 8 pixels when it holds a VTK
    projected-tetrahedra volume (a time series of meshes, ``vtk_scene.volume_prop``). VTK 9.7's
    vtkOpenGLProjectedTetrahedraMapper (seen on Mesa llvmpipe) leaves cells out of the first frame a render window
    draws with it (later frames are whole, any size, camera or new input): ``volviz render`` of the OpenFOAM cavity
    dropped the lid strip's far half, RMSE 5.8 against the app's screen, which draws many frames (issue #28). At 8 x 8
    the extra draw costs the mapper's sort and no rasterisation to speak of."""
    volumes = plotter.renderer.GetVolumes()
    if not any(isinstance(cast("vtkVolume", volumes.GetItemAsObject(i)).GetMapper(), vtk.vtkProjectedTetrahedraMapper)
               for i in range(volumes.GetNumberOfItems())):   # (a volume collection holds vtkVolumes)
        return
    window = plotter.render_window
    width, height = window.GetSize()
    window.SetSize(8, 8)
    window.Render()
    window.SetSize(width, height)
