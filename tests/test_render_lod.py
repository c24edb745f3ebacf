"""LOD block rendering of a compressed volume in a real offscreen PyVista plotter (volviz.render.lod_volume), with
our ray caster (default) and VTK's multi-block mapper: blocks of one level join without seams, opaque geometry hides
the volume through the depth buffer, the selection follows the camera and budget, and the transfer function,
visibility and clipping reach the image."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from conftest import blob_vvz

pv = pytest.importorskip("pyvista")

from volviz.optics import TransferFunction  # noqa: E402
from volviz.regular.lod import LodTree, Selection  # noqa: E402
from volviz.regular.wavelet import HALF  # noqa: E402
from volviz.optics.metrics import max_abs, rmse  # noqa: E402
from volviz.regular.raycast import render_blocks, render_reference  # noqa: E402
from volviz.render.lod_volume import LodVolume  # noqa: E402
from volviz.model.camera import Camera  # noqa: E402

SIZE = (160, 120)
TF = TransferFunction([20.0, 100.0, 255.0], [[1.0, 0.6, 0.2], [0.3, 0.6, 1.0], [1.0, 1.0, 1.0]], [0.0, 0.08, 0.2])


@pytest.fixture(scope="module")
def tree(tmp_path_factory) -> LodTree:
    # 72: not a multiple of the node size, so there are partial edge nodes
    return LodTree(blob_vvz(Path(tmp_path_factory.mktemp("lod")) / "blob.vvz", 72), cache_bytes=32 << 20)


def _shot(pl: "pv.Plotter") -> np.ndarray:
    pl.ren_win.Render()                 # PyVista's screenshot() does not notice changes made behind its back
    return pl.screenshot(return_img=True)


def _plotter() -> "pv.Plotter":
    pl = pv.Plotter(off_screen=True, window_size=list(SIZE))
    pl.set_background("black")
    pl.camera_position = [(160.0, -110.0, 90.0), (36.0, 36.0, 36.0), (0, 0, 1)]
    return pl


def _level_selection(tree: LodTree, level: int) -> Selection:
    c = tree.decoder.n_nodes(level)
    return Selection([(level, (i, j, k)) for i in range(c[0]) for j in range(c[1]) for k in range(c[2])])


def _level_volume(tree: LodTree, level: int) -> np.ndarray:
    """All nodes of one level put together into one array (no overlap), in data units."""
    c = tree.decoder.n_nodes(level)
    parts = {p: tree.node((level, p)) for p in np.ndindex(*c)}
    shape = [sum(parts[tuple(q if a == ax else 0 for a, q in enumerate((i, i, i)))].shape[ax] for i in range(c[ax]))
             for ax in range(3)]
    out = np.zeros(shape, np.int32)
    for p, a in parts.items():
        s = tuple(slice(p[ax] * HALF, p[ax] * HALF + a.shape[ax]) for ax in range(3))
        out[s] = a
    return tree._to_data(out).astype(np.float32)


def test_vtk_blocks_of_one_level_join_without_seams(tree: LodTree) -> None:
    level = 1                                          # 36^3 samples in 3 x 3 x 3 blocks of up to 16^3
    sel = _level_selection(tree, level)
    assert len(sel.nodes) == 27
    pl = _plotter()
    try:
        lod = LodVolume(pl, tree, TF, renderer="vtk")
        lod.show(sel, lod.decode(sel))
        blocks = _shot(pl).astype(float)
        lod.remove()
        whole = _level_volume(tree, level)
        step = tree.spacing * (1 << level)
        grid = pv.ImageData(dimensions=whole.shape, spacing=tuple(step), origin=tuple(tree.origin))
        grid.point_data["scalars"] = whole.ravel(order="F")
        one = LodVolume(pl, tree, TF, renderer="vtk")      # the same mapper with the level as a single block
        import vtk

        mb = vtk.vtkMultiBlockDataSet()
        mb.SetNumberOfBlocks(1)
        mb.SetBlock(0, grid)
        one.mapper.SetInputDataObject(mb)
        single = _shot(pl).astype(float)
    finally:
        pl.close()
    lit = single.sum(axis=2) > 30
    assert lit.mean() > 0.2                                # the volume fills a good part of the view
    d = np.abs(blocks - single)
    rmse = float(np.sqrt((d ** 2).mean()))
    # measured: RMSE 0.52, 99.9th percentile 2.4 of 255 (max 13 on single silhouette pixels); the same blocks
    # without their one-voxel overlap leave gaps along the block faces: RMSE 7.6, 99.9th percentile 46
    assert rmse < 2.0, rmse
    assert float(np.percentile(d, 99.9)) < 12.0


def test_volviz_blocks_of_one_level_join_without_seams(tree: LodTree) -> None:
    level = 1                                          # 36^3 samples at level-0 positions 0, 2, ..., 70
    sel = _level_selection(tree, level)
    pl = _plotter()
    try:
        lod = LodVolume(pl, tree, TF)
        lod.show(sel, lod.decode(sel))
        shot = _shot(pl).astype(float)
        cam = Camera.from_pyvista(pl.renderer.GetActiveCamera())
    finally:
        pl.close()
    assert lod.stats["renderer"] == "volviz" and lod.stats["render_s"] > 0
    # the level as one volume, exact: its last sample (70) is extended to the volume's end (71) as the blocks do
    whole = np.pad(_level_volume(tree, level).astype(np.float64), ((0, 1),) * 3, mode="edge")
    keep = np.array([[-1.0, 0, 0, 71.0], [0, -1.0, 0, 71.0], [0, 0, -1.0, 71.0]])
    ref = render_reference(whole, tree.origin, tree.spacing * 2, TF, cam, SIZE, step=0.25, planes=keep)
    assert ref[..., 3].mean() > 0.2
    # measured: RMSE 0.08, max 1.9 of 255 (the premultiplied float image; no lines along the block faces)
    assert rmse(lod.image, ref) < 0.3 and max_abs(lod.image, ref) < 4.0, (rmse(lod.image, ref), max_abs(lod.image, ref))
    # what the window shows, through the 8-bit straight-alpha overlay: measured RMSE 0.31, 99.9th percentile 1.4
    d = np.abs(shot - np.clip(ref[..., :3], 0, 1) * 255)
    assert float(np.sqrt((d ** 2).mean())) < 1.0 and float(np.percentile(d, 99.9)) < 4.0


def test_volviz_opaque_geometry_hides_the_volume_behind_it(tree: LodTree) -> None:
    pl = _plotter()
    try:
        free = LodVolume(pl, tree, TF, budget=16)
        free.update()
        alpha_free = free.image[..., 3].copy()
        free.remove()
        pl.add_mesh(pv.Sphere(radius=22.0, center=(36.0, 36.0, 36.0)), color="red")
        lod = LodVolume(pl, tree, TF, budget=16)     # not drawn yet; its overlay has switched multisampling off
        scene = _shot(pl).astype(float)
        lod.update()
        shot = _shot(pl).astype(float)
        cam = Camera.from_pyvista(pl.renderer.GetActiveCamera())
        depth = lod.depth
    finally:
        pl.close()
    assert depth is not None and np.isfinite(depth).mean() > 0.05        # the sphere covers part of the view
    hidden = np.isfinite(depth)
    assert lod.image[..., 3][hidden].mean() < alpha_free[hidden].mean() - 0.1   # less volume in front of the sphere
    assert np.array_equal(lod.image[..., 3][~hidden], alpha_free[~hidden])     # the rest is unchanged
    same = render_blocks(lod._pool, TF, cam, SIZE, depth=depth)      # the library call with that depth
    assert max_abs(same, lod.image) < 0.1                           # (its table spans another scalar range)
    # the window shows the premultiplied "over": C_vol + (1 - a_vol) C_scene (8-bit straight-alpha upload)
    expect = np.clip(lod.image[..., :3], 0, 1) * 255 + (1 - lod.image[..., 3:4]) * scene
    d = np.abs(shot - expect)
    assert float(np.sqrt((d ** 2).mean())) < 1.0 and float(np.percentile(d, 99.9)) < 3.0, (d.max(), d.mean())


def test_volviz_ray_casts_in_the_background_worker(tree: LodTree) -> None:
    """``camera()`` (GUI thread) captures what the ray cast needs from the plotter (camera, opaque depth, planes);
    ``decode`` on a worker then ray casts, and ``show`` only uploads, giving exactly the image a draw on the GUI
    thread makes, with opaque geometry in the scene too; a camera moved before ``show`` is drawn again."""
    from concurrent.futures import ThreadPoolExecutor

    def on_worker(cam):                                     # the app's worker: select + decode
        with ThreadPoolExecutor(1) as ex:
            return ex.submit(lambda: (lambda s: (s, lod.decode(s)))(lod.select(cam))).result()

    pl = _plotter()
    try:
        lod = LodVolume(pl, tree, TF, budget=16)
        lod.update()
        assert lod.stats["prepared"] is True and lod.depth is None          # nothing else in the scene
        pl.camera_position = [(150.0, -120.0, 100.0), (36.0, 36.0, 36.0), (0, 0, 1)]
        sel, blocks = on_worker(lod.camera())
        lod.show(sel, blocks)
        assert lod.stats["prepared"] is True and lod.stats["render_s"] > 0
        shown = lod.image.copy()
        again = lod.draw()                                  # the same view drawn on this thread
        assert max_abs(shown, again) == 0.0
        moved, moved_blocks = on_worker(lod.camera())
        pl.camera_position = [(160.0, -110.0, 90.0), (36.0, 36.0, 36.0), (0, 0, 1)]   # moved before show
        lod.show(moved, moved_blocks)
        assert lod.stats["prepared"] is False                # drawn again for the camera it has now
        assert max_abs(lod.image, shown) > 1.0
        no_sphere = lod.image.copy()
        pl.add_mesh(pv.Sphere(radius=22.0, center=(36.0, 36.0, 36.0)), color="red")
        sel, blocks = on_worker(lod.camera())
        lod.show(sel, blocks)
        assert lod.stats["prepared"] is True and lod.depth is not None and np.isfinite(lod.depth).any()
        with_depth = lod.image.copy()
        assert max_abs(with_depth, lod.draw()) == 0.0       # the GUI-thread draw against the depth: the same image
        assert with_depth[..., 3].sum() < no_sphere[..., 3].sum() - 1.0    # the sphere hides part of the volume
    finally:
        pl.close()


def test_volviz_honours_the_mapper_clipping_planes(tree: LodTree) -> None:
    import vtk

    pl = _plotter()
    try:
        lod = LodVolume(pl, tree, TF, budget=16)
        lod.update()
        whole = lod.image.copy()
        plane = vtk.vtkPlane()
        plane.SetOrigin(36.0, 36.0, 36.0)
        plane.SetNormal(0.0, 0.0, -1.0)                     # VTK keeps the side the normal points to: z <= 36
        lod.mapper.AddClippingPlane(plane)                  # as volviz.render.clipping does for the controller
        cut = lod.draw()
        cam = Camera.from_pyvista(pl.renderer.GetActiveCamera())
        same = render_blocks(lod._pool, TF, cam, SIZE, planes=np.array([[0.0, 0.0, -1.0, 36.0]]), table=lod._table)
    finally:
        pl.close()
    assert cut[..., 3].sum() < 0.8 * whole[..., 3].sum()
    assert max_abs(same, cut) == 0.0                        # the plane reaches the rays as n . X + w >= 0


@pytest.mark.parametrize("renderer", ["volviz", "vtk"])
def test_selection_follows_budget_and_camera(tree: LodTree, renderer: str) -> None:
    pl = _plotter()
    try:
        lod = LodVolume(pl, tree, TF, budget=4, renderer=renderer)
        coarse = dict(lod.update())
        img_coarse = _shot(pl)
        lod.budget = 64
        fine = dict(lod.update())
        img_fine = _shot(pl)
        assert coarse["blocks"] <= 4 < fine["blocks"] <= 64
        assert min(fine["levels"]) < min(coarse["levels"])    # more budget: finer levels
        assert np.abs(img_fine.astype(int) - img_coarse.astype(int)).max() > 10
        again = dict(lod.update())                             # same view: nothing new to decode
        assert again["new_blocks"] == 0 and again["blocks"] == fine["blocks"]
        lod.set_transfer_function(TF.scaled_extinction(0.0))
        assert _shot(pl).max() == 0       # fully transparent TF: nothing drawn
    finally:
        pl.close()


def test_session_with_a_lod_dataset_follows_camera_and_transfer_function(tree: LodTree) -> None:
    from volviz.render.controller import SceneController
    from volviz.render.offscreen import offscreen_plotter
    from volviz.scene.datasets import load_datasets
    from volviz.scene.lod import LOD_VOXELS, vvz_voxels
    from volviz.scene.opening import data_session
    from volviz.session import CameraState, Component, DatasetRef, RenderSettings, Session

    vvz = Path(tree.decoder.path)
    assert vvz_voxels(vvz) == 72 ** 3 < LOD_VOXELS
    assert "lod" not in data_session(vvz).datasets[0].options          # small files are decoded whole
    session = Session(datasets=[DatasetRef(id="blob", path=str(vvz), options={"lod": True})],
                      components=[Component(id="blob", type="volume", dataset="blob", settings={"budget": 8})],
                      render=RenderSettings(size=SIZE, background=(0.0, 0.0, 0.0),   # the image is the volume's:
                                            options={"scalar_bar": False, "axes": False, "outline": False}))
    datasets = load_datasets(session, None)
    assert isinstance(datasets["blob"], LodTree)
    plotter = offscreen_plotter(SIZE)
    try:
        controller = SceneController(plotter, session, datasets)
        controller.build()
        lod = controller.props["blob"]
        assert isinstance(lod, LodVolume) and 1 <= lod.stats["blocks"] <= 8
        far = _shot(plotter)
        assert far.std() > 3.0                                              # default TF fitted to the data
        controller.set_camera(CameraState(position=(36.0, -60.0, 36.0), focal_point=(36.0, 36.0, 36.0)))
        near_sel = list(lod.selection.nodes)
        assert _shot(plotter).std() > 3.0
        controller.set_camera(CameraState(position=(400.0, -300.0, 250.0), focal_point=(36.0, 36.0, 36.0)))
        assert list(lod.selection.nodes) != near_sel                        # a new view, a new selection
        tf = controller.transfer_function("blob")
        controller.set_transfer_function("blob", tf.scaled_extinction(0.0))
        assert _shot(plotter).max() == 0                                    # the TF reaches the blocks
        controller.set_transfer_function("blob", tf)
        assert _shot(plotter).std() > 3.0
        controller.set_visible("blob", False)
        assert not lod.volume.GetVisibility()
        assert _shot(plotter).max() == 0                                    # the overlay follows the visibility
    finally:
        plotter.close()
