"""The rule behind two freezes (issue #28): a background job makes no VTK object and hands none to the GUI thread.

A worker that makes a VTK object from Python holds the GIL while VTK's garbage collector may wait for a collection
on the GUI thread, and that collection, inside a render (GIL released), may be freeing a PyVista object whose
clean-up needs the GIL: each waits for the other (the terrain, b9391d2; a playing surface series,
test_flow_play_orbit). So the jobs hand over arrays (model datasets, meshes) and the GUI thread makes the VTK objects.

Each real file is opened in the real window and each job kind the app submits for it is run as the app runs it, on
a thread of its own under ``vtk_threads.on_worker``: the view updates (``view.compute``: PT volume, natural scene),
the preparation of a component (what loading and showing run: ``prepare_component``), the first look's transfer
function (``default_transfer_function_for``, in the loading job), the set-up of a CPU ray-cast volume (its VTK work
on the set-up window's thread, ``volviz.render.volume_setup``), the time blend of a series (``blend_volume``). Not covered, still making VTK objects on workers: isosurface extraction and cuts (VTK's
contour, clip and probe filters inside ``volviz.iso``) and frame export."""
from __future__ import annotations

import pytest

from conftest import data_file
from flows import wait_loaded, wait_settled
from vtk_threads import on_worker, vtk_objects_in

FILES = ["bluntfin/bluntfinxyz.bin", "terrain/SainteHelens.dem", "volumes/hydrogen.vti",
         "ecosystem/openfoam-cavity/case.foam", "ecosystem/tos_O1_2001-2002.nc"]


def _clean(job: str, run) -> object:
    result, calls = on_worker(run)
    assert calls == [], (job, calls[:6])
    assert vtk_objects_in(result) == [], job
    return result


@pytest.mark.parametrize("name", FILES)
def test_the_jobs_of_a_shown_file_make_no_vtk_object(qtbot, make_window, name: str) -> None:
    from volviz.render.vtk_scene import default_transfer_function_for

    window = make_window()
    window.resize(600, 400)
    window.open_path(data_file(name))
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    controller = window.controller
    jobs = 0
    for key, view in controller.camera_views().items():
        request = view.begin()
        result = _clean(f"{key} compute", lambda: view.compute(request))
        view.finish(request, *result)
        jobs += 1
    for comp in controller.session.components:
        if comp.dataset is not None:
            _clean(f"prepare {comp.id}", lambda: controller.prepare_component(comp.id))
            jobs += 1
        if comp.type == "volume":   # what loading runs for a component without a transfer function yet
            _clean(f"first look {comp.id}", lambda: default_transfer_function_for(controller.dataset_of(comp.id)))
    setup = window.scene_loading.volume_setup
    if setup is not None:          # a regular volume drawn by the CPU ray caster: the loading's set-up job
        ticket = setup.hold(controller.volumes_to_set_up(controller.prepare()))
        assert _clean("volume set-up", lambda: setup.run(ticket)) == 1
        setup.release(ticket)
        jobs += 1
    for comp_id in controller.time_volumes():
        frame = _clean(f"blend {comp_id}", lambda: controller.blend_volume(comp_id, controller.time))
        controller.show_volumes({comp_id: frame})   # and the GUI thread makes its VTK input
        jobs += 1
    assert jobs >= 1
