"""The artefacts issue #28 found in the final pictures, each checked on the real picture (real VTK rendering on the
machine's OpenGL driver; the app under pytest-qt)."""
from __future__ import annotations

import numpy as np

from conftest import data_file
from flows import open_blunt_fin, screen, wait_settled


def _luma(img: np.ndarray) -> np.ndarray:
    return img[..., :3].astype(np.float64) @ np.array([0.299, 0.587, 0.114])


def _dark_steps(img: np.ndarray, band: np.ndarray, levels: float) -> int:
    """Pixels of ``band`` darker than both horizontal or both vertical neighbours by more than ``levels``."""
    y = _luma(img)
    p = np.pad(y, 1, mode="edge")
    horizontal = (y < p[1:-1, :-2] - levels) & (y < p[1:-1, 2:] - levels)
    vertical = (y < p[:-2, 1:-1] - levels) & (y < p[2:, 1:-1] - levels)
    return int(((horizontal | vertical) & band).sum())


def _near(mask: np.ndarray, r: int) -> np.ndarray:
    out = mask.copy()
    for dy in range(-r, r + 1):
        for dx in range(-r, r + 1):
            out |= np.roll(np.roll(mask, dy, 0), dx, 1)
    return out


def test_cpu_pt_preview_leaves_no_dark_steps_along_the_box(qtbot, make_window) -> None:
    """Blunt Fin, CPU PT, the preview the app shows while the camera moves (``begin(scale=MOVING_SCALE)``): along the
    outline box's edges it has no more dark steps (pixels darker than both neighbours by > 8 levels) than the still
    frame, give or take 2 % of the box's pixels. Cut per block at the nearest depth, the preview had a dark
    staircase beside the box's near edges: measured 588 such pixels against 26 in the still frame (1524 box
    pixels, a 524 x 554 viewport); with ``preview_upsample`` 35."""
    from volviz.render.decorations import OUTLINE_NAME
    from volviz.render.pt_prop import PTVolume
    from volviz_app.view_scheduler import MOVING_SCALE

    window = open_blunt_fin(qtbot, make_window)
    wait_settled(qtbot, window)
    cpu = next(v for v in window.controller.props.values() if isinstance(v, PTVolume))
    outline = window.plotter.renderer.actors[OUTLINE_NAME]
    still = screen(window)
    cpu.visible = False
    bare = screen(window)
    outline.SetVisibility(False)
    empty = screen(window)
    outline.SetVisibility(True)
    cpu.visible = True
    box = np.abs(bare - empty).max(axis=-1) > 30
    assert box.sum() > 500, "the outline box is not on screen"
    band = _near(box, 2)
    request = cpu.begin(scale=MOVING_SCALE)
    cpu.finish(request, *cpu.compute(request))
    w, h = window.plotter.ren_win.GetSize()
    assert cpu.stats["size"] == (w // MOVING_SCALE, h // MOVING_SCALE)
    preview = screen(window)
    assert np.abs(preview - bare).max() > 100, "the volume preview is not on screen"
    steps_still, steps_preview = _dark_steps(still, band, 8), _dark_steps(preview, band, 8)
    assert steps_preview <= steps_still + 0.02 * box.sum(), (steps_preview, steps_still, int(box.sum()))


def _render_flat_picture(size: tuple[int, int], outline: bool) -> np.ndarray:
    import warnings

    from volviz.render.export import render_session
    from volviz.scene.opening import data_session

    session = data_session(data_file("sky/clouds.jpeg"))
    session.render.options["outline"] = outline
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return render_session(session, None, size).astype(int)


def test_flat_picture_outline_draws_all_four_sides() -> None:
    """clouds.jpeg shown flat and face-on (``volviz render``, single-sampled on llvmpipe): the outline box is the
    picture's own border, and every side of it is drawn along its whole length. Before, the picture's border pixels
    won the depth tie under the top, bottom and right sides: 64 outline pixels at 160 x 120 (the left side only),
    none at 161 x 121; now all four sides."""
    for size in ((160, 120), (161, 121)):
        boxed, bare = _render_flat_picture(size, True), _render_flat_picture(size, False)
        line = np.abs(boxed - bare).sum(axis=2) > 30
        picture = np.abs(bare - bare[0, 0]).sum(axis=2) > 10
        rows = np.nonzero(picture[:, size[0] // 4: 3 * size[0] // 4].any(axis=1))[0]   # clear of the axes widget
        cols = np.nonzero(picture[size[1] // 3: 2 * size[1] // 3].any(axis=0))[0]
        top, bottom, left, right = rows.min(), rows.max(), cols.min(), cols.max()
        width, height = right - left + 1, bottom - top + 1
        assert width > 0.6 * size[0] and height > 0.3 * size[1], (size, top, bottom, left, right)
        sides = {"top": line[top - 1: top + 1, left:right + 1].any(axis=0).mean(),
                 "bottom": line[bottom: bottom + 2, left:right + 1].any(axis=0).mean(),
                 "left": line[top:bottom + 1, left - 1: left + 1].any(axis=1).mean(),
                 "right": line[top:bottom + 1, right: right + 2].any(axis=1).mean()}
        assert min(sides.values()) > 0.9, (size, sides)


def test_outline_corners_are_the_bounds_at_utm_coordinates(tmp_path) -> None:
    """A grid placed at UTM coordinates (x 500000.3, y 7000000.3 m): the outline box's corners are its bounds to a
    micrometre (float32 points, as ``pv.Box`` made them, were 0.2 m off in y)."""
    import warnings

    import pyvista as pv

    from volviz.render.controller import SceneController
    from volviz.render.decorations import OUTLINE_NAME
    from volviz.render.offscreen import offscreen_plotter
    from volviz.scene.datasets import load_datasets
    from volviz.scene.opening import data_session

    grid = pv.ImageData(dimensions=(6, 5, 4), spacing=(1.7, 1.3, 0.9), origin=(500000.3, 7000000.3, 100.1))
    grid.point_data["h"] = np.arange(grid.n_points, dtype=np.float64)
    path = tmp_path / "utm.vti"
    grid.save(path)
    session = data_session(path)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        datasets = load_datasets(session, None)
    plotter = offscreen_plotter((160, 120))
    try:
        SceneController(plotter, session, datasets).build()
        points = np.asarray(plotter.renderer.actors[OUTLINE_NAME].GetMapper().GetInput().GetPoints().GetData())
        lo, hi = np.array(grid.bounds[::2]), np.array(grid.bounds[1::2])
        assert np.abs(points.min(axis=0) - lo).max() < 1e-6 and np.abs(points.max(axis=0) - hi).max() < 1e-6
        assert len({tuple(p) for p in points}) == 8
    finally:
        plotter.close()


def test_point_cloud_shown_by_a_colour_array_has_no_scalar_bar(tmp_path) -> None:
    """A point table with intensity and red, green, blue columns: shown by intensity (its default) it has a scalar
    bar named after it; ``--array red`` draws the points in their own colours (``vtk_scene.surface_input``), so the
    "red" scalar bar it kept before explains nothing and is gone (and the framing keeps no room for it)."""
    import warnings

    from volviz.render.decorations import legend_margin, scalar_bar_actor, scalar_bar_title
    from volviz.render.export import close_scene, offscreen_scene, open_target, snapshot
    from volviz.scene.datasets import load_datasets

    rng = np.random.default_rng(7)
    points = rng.random((400, 3))
    colors = (points * 255).astype(int)
    rows = [f"{p[0]},{p[1]},{p[2]},{7 * p[0]},{c[0]},{c[1]},{c[2]}" for p, c in zip(points, colors)]
    path = tmp_path / "cloud.csv"
    path.write_text("\n".join(["x,y,z,intensity,red,green,blue"] + rows) + "\n")
    for array, title in ((None, "intensity"), ("red", None)):
        session, _ = open_target(path, array=array)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            datasets = load_datasets(session, None)
        plotter, controller = offscreen_scene(session, datasets, (160, 120))
        try:
            controller.build()
            image = snapshot(plotter, (160, 120)).astype(int)
            assert scalar_bar_title(plotter) == title
            assert (scalar_bar_actor(plotter) is None) == (title is None)
            assert (legend_margin(session, datasets) == 0.0) == (title is None)
        finally:
            close_scene(plotter, controller)
        if array == "red":   # the points in their own colours: reddish and bluish ones both on screen
            drawn = image[np.abs(image - image[0, 0]).sum(axis=2) > 60]
            assert ((drawn[:, 0] > drawn[:, 2] + 60).sum() > 3) and ((drawn[:, 2] > drawn[:, 0] + 60).sum() > 3)
