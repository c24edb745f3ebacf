"""What the GUI thread would otherwise import (or make) in the middle of its work, imported at start-up instead (the
window calls ``import_gui_thread_modules`` once, before its first scene), so a first use does not block the event
loop."""
from __future__ import annotations


def import_gui_thread_modules() -> None:
    """Import at start-up what the GUI thread later imports inside functions: a first ``import vtk`` (the natural
    scene's overlay) blocked the event loop in the middle of loading a scene (docs/bench/docstring-figures.md)."""
    import volviz.nature.nature_scene  # noqa: F401
    import volviz.render.controller  # noqa: F401
    import volviz.render.pt_prop  # noqa: F401
    import volviz.render.scene_builder  # noqa: F401
    import volviz.render.vtk_facade  # noqa: F401
    import pyvista
    import scipy.optimize  # noqa: F401 - the iso-spectrum fit's least squares, when an isosurface is first shown

    from volviz.io.registry import reader_specs

    # every reader's file-name patterns resolved now (meshio's extensions import meshio, the plugins' entry points are
    # read): a first File > Open did it on the GUI thread, 80-150 ms of a blocked event loop while a session loaded
    for spec in reader_specs():
        spec.globs()

    # the thread and offscreen window that set up CPU ray-cast volumes before they are shown
    # (volviz.render.volume_setup): making an OpenGL window holds the GIL, 40-100 ms here, which stalled the event
    # loop in the first load that made it
    # (the window releases it when it closes: ``volume_setup.release_shared``)
    from volviz.render.volume_setup import acquire_shared

    acquire_shared()

    # pyvista asks once per process whether this system can plot (it runs ``xset -q``) when the first offscreen plotter
    # of an export is made: ~60 ms of a blocked event loop at the start of the first export, here at start-up instead
    pyvista.system_supports_plotting()
