"""An offscreen PyVista plotter of a given size: what export, the benches and the OpenGL probe of
``volviz.render.backend`` render into (EGL or OSMesa without a display, llvmpipe on a machine without a GPU)."""
from __future__ import annotations

import os
from typing import Any

import pyvista as pv

from volviz.render.vtk_facade import vtk


def offscreen_plotter(size: tuple[int, int]) -> Any:
    """A ``pyvista.Plotter`` that renders off screen at ``size`` (width, height) pixels."""
    if not os.environ.get("DISPLAY"):  # VTK tries X first and warns before it falls back to EGL: not the user's concern
        vtk.vtkLogger.SetStderrVerbosity(vtk.vtkLogger.VERBOSITY_ERROR)
    return pv.Plotter(off_screen=True, window_size=[int(size[0]), int(size[1])])
