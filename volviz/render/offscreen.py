"""An offscreen PyVista plotter of a given size: what export, the benches and the OpenGL probe of
``volviz.render.backend`` render into (EGL or OSMesa without a display, llvmpipe on a machine without a GPU)."""
from __future__ import annotations

import os
from typing import Any

import pyvista as pv
from pyvista.plotting import plotter as pyvista_plotter

from volviz.render.vtk_facade import vtk


def offscreen_plotter(size: tuple[int, int]) -> Any:
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
    probe = getattr(pyvista_plotter, "_warn_xserver", None)
    if probe is not None and not hasattr(probe, "has_support"):
        probe.has_support = True
