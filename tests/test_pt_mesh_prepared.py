"""A PT volume's mesh is prepared with what its first visibility order reads (``volviz.scene.tetra``): the face
adjacency and the boundary faces off the convex hull are built on the loading thread, not in the first frame, which
a GPU PT volume draws on the GUI thread (issue #28: no event-loop stall over 100 ms; for the Blunt Fin's 187,318
tetrahedra they took 110-200 ms there)."""
from __future__ import annotations

import numpy as np
import pyvista as pv

from conftest import data_file
from volviz.io import read
from volviz.model.clip import ClipPlane, ClipSettings
from volviz.model.datasets import TetMesh
from volviz.render.scene_builder import install_scene, prepare_scene
from volviz.scene.opening import data_session
from volviz.scene.tetra import cut_tetmesh, pt_mesh
from volviz.unstructured import topology as topology_module
from volviz.unstructured.topology import cell_ranges, topology


def _two_cubes_apart() -> TetMesh:
    """Two unit cubes of 5 tetrahedra each, 1 apart along x: not convex (the gap's faces are off the hull)."""
    cube = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0, 0, 1], [1, 0, 1], [0, 1, 1], [1, 1, 1]], float)
    tets = np.array([[0, 1, 2, 4], [1, 3, 2, 7], [1, 4, 5, 7], [2, 4, 7, 6], [1, 2, 4, 7]])
    points = np.vstack([cube, cube + [2.0, 0.0, 0.0]])
    return TetMesh(points, np.vstack([tets, tets + 8]), np.arange(16, dtype=float))


def test_a_pt_mesh_and_its_cut_come_with_their_adjacency_and_inner_boundary() -> None:
    mesh = pt_mesh(_two_cubes_apart())
    topo = topology(mesh)
    assert "neighbor" in vars(topo) and "back_face" in vars(topo)     # built, not left to the first use
    assert topo.inner_boundary_faces is not None and len(topo.inner_boundary_faces) == 4   # the gap's 2 x 2 faces
    cut = cut_tetmesh(mesh, ClipSettings(planes=(ClipPlane((0.5, 0.0, 0.0), (1.0, 0.0, 0.0)),)))
    assert cut is not None
    cut_topo = topology(cut)
    assert "neighbor" in vars(cut_topo) and cut_topo.inner_boundary_faces is not None


def test_a_pt_mesh_and_its_cut_come_with_their_cells_scalar_ranges() -> None:
    """The cells' scalar ranges that a PT view culls by (``visible_cells``, made as a GPU PT volume is made on the GUI
    thread: 33 ms of a 124 ms stall opening the Blunt Fin) are built with the mesh."""
    mesh = pt_mesh(_two_cubes_apart())
    cached = topology_module._RANGES.get(mesh)
    assert cached is not None and cached[1] is cell_ranges(mesh)
    np.testing.assert_array_equal(cached[1].smin, mesh.scalars[mesh.tets].min(axis=1))
    cut = cut_tetmesh(mesh, ClipSettings(planes=(ClipPlane((0.5, 0.0, 0.0), (1.0, 0.0, 0.0)),)))
    assert cut is not None and topology_module._RANGES.get(cut) is not None


def test_vtks_projected_tetrahedra_draw_volvizs_tetrahedra_made_on_the_loading_thread() -> None:
    """Render method "vtk": the Blunt Fin's curvilinear grid is tetrahedralised by ``prepare_scene`` (any thread) as
    for volviz's own PT, and VTK's mapper draws those cells, as an image of a window of a thread of its own
    (``volviz.render.vtk_pt_image``; before, the mapper drew in the scene's window on the GUI thread, after
    ``install_component`` ran vtkDataSetTriangleFilter there: 224,874 tetrahedra, 0.4-0.6 s)."""
    session = data_session(data_file("bluntfin/bluntfinxyz.bin"), None)
    session.render.method = "vtk"
    datasets = {"data": read(data_file("bluntfin/bluntfinxyz.bin"))}
    prepared = prepare_scene(session, datasets)
    (comp_id, mesh), = prepared.parts.items()
    assert isinstance(mesh, TetMesh) and len(mesh.tets) == 187318
    plotter = pv.Plotter(off_screen=True, window_size=(64, 48))
    try:
        views = install_scene(plotter, session, datasets, prepared, views=False)
        view = views[comp_id]
        assert view.kind == "pt" and view.method == "vtk" and view.mesh is mesh
        assert plotter.renderer.GetVolumes().GetNumberOfItems() == 0      # nothing of it drawn in the scene's window
        view.update()
        drawn = view._thread_images.gl.state["volume"].GetMapper().GetInput()
        assert drawn.GetNumberOfCells() == len(mesh.tets)
        np.testing.assert_array_equal(pv.wrap(drawn).points, mesh.points)
        assert view.image[..., 3].max() > 0.5 and view.stats["method"] == "vtk"
        view.remove()
    finally:
        plotter.close()


_KERNELS_LOADED = """
import numpy as np
from volviz.scene.tetra import pt_mesh
from volviz.unstructured import index_buffer, probe
from volviz.unstructured.synthetic import box_tets

assert not probe._ray_spans.signatures and not index_buffer.fill_triangles.signatures
pt_mesh(box_tets(2))
assert len(probe._ray_spans.signatures) == 1
assert [str(t) for t in index_buffer.fill_triangles.signatures[0][:2]] == [
    "array(int32, 1d, C)", "array(bool, 1d, C)"]
"""


def test_a_pt_mesh_is_prepared_with_the_kernels_the_gui_thread_calls_first_loaded() -> None:
    """A Numba kernel's first call in a process loads it holding the GIL: the GPU volume's static index buffer
    (filled as it is installed, on the GUI thread: 233 ms in the flow-gap survey) and the probe under the cursor (494
    ms). ``pt_mesh``, on the loading thread, loads both, with the types of those calls. In a fresh process: no other
    test has called them."""
    import subprocess
    import sys

    run = subprocess.run([sys.executable, "-c", _KERNELS_LOADED], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
