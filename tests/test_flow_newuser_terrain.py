"""A new user's flow on a file no other flow test opens (issue #28, "try it as a new user would"): Mount St. Helens
(``terrain/SainteHelens.dem``, a USGS DEM opened as terrain under a sky), orbited with three mouse drags; at the end
the screen matches ``volviz render`` of the saved session.

Found by driving the window so: the window froze for good during the first drag. The natural scene's background job
made the terrain's VTK poly data on its worker thread, holding the GIL inside VTK's garbage collector, while the GUI
thread's render (GIL released) collected the previous terrain, a PyVista object whose clean-up needs the GIL: each
waited on the other. The views now hand the terrain over as arrays and make its poly data in ``finish``, on the GUI
thread. Bound on the picture: as the other flow tests (the same scene, renderers, camera and size: RMSE < 1.5, under
0.5 % of the pixels off by more than 24 levels)."""
from __future__ import annotations

import threading

import numpy as np
from vtkmodules.vtkCommonCore import vtkObjectBase

from conftest import data_file
from flows import compare_with_render, drag_viewport, wait_loaded, wait_settled


def test_orbiting_a_terrain_settles_at_the_picture_volviz_renders(qtbot, make_window, tmp_path) -> None:
    window = make_window()
    window.open_path(data_file("terrain/SainteHelens.dem"))
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    for dx, dy in ((180, 40), (-120, 30), (90, -50)):
        drag_viewport(qtbot, window, dx, dy)
    wait_settled(qtbot, window)
    assert window.error_dialog is None
    err = compare_with_render(window, tmp_path, "terrain")
    assert err["rmse"] < 1.5 and err["off"] < 0.005, err

    # what the background job hands over is no VTK object: made on a worker, one could deadlock a render
    view = window.controller.nature
    request = view.begin()
    made: list = []
    worker = threading.Thread(target=lambda: made.append(view.compute(request)))
    worker.start()
    worker.join()
    mesh = made[0][0]
    assert not isinstance(mesh, vtkObjectBase) and len(mesh.points) > 1000
    view.finish(request, *made[0])
    assert np.array_equal(np.asarray(view.terrain_actor.mapper.GetInput().GetPoints().GetData()), mesh.points)
