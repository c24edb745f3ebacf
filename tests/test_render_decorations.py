"""The scalar bar, orientation axes and outline box (volviz.render.decorations): on by default, named after the shown
array with its range, switched off by the session's render options, and re-drawn when the transfer function changes."""
from __future__ import annotations

import warnings

import numpy as np
import pytest

from conftest import data_file
from volviz.render.decorations import OUTLINE_NAME, scalar_bar_actor, scalar_bar_title


def _scene(path, **options):
    from volviz.render.controller import SceneController
    from volviz.render.export import offscreen_plotter
    from volviz.render.scene_builder import data_session, load_datasets

    session = data_session(path)
    session.render.options.update(options)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        datasets = load_datasets(session, None)
    plotter = offscreen_plotter((320, 240))
    controller = SceneController(plotter, session, datasets)
    controller.build()
    return plotter, controller


def test_scalar_bar_axes_and_outline_by_default():
    plotter, controller = _scene(data_file("volumes/neghip.slc"))
    try:
        bar = scalar_bar_actor(plotter)
        assert bar is not None and scalar_bar_title(plotter) == "SLCImage"      # the SLC header's name
        tf = controller.transfer_function("data")
        assert bar.GetLookupTable().GetRange() == pytest.approx(tf.range)
        outline = plotter.renderer.actors[OUTLINE_NAME]
        assert outline.GetBounds() == pytest.approx((0.0, 65.0, 0.0, 65.0, 0.0, 65.0))
        assert plotter.renderer.axes_widget is not None and plotter.renderer.axes_widget.GetEnabled()
        image = np.asarray(plotter.screenshot(None, return_img=True))
        right = image[:, int(0.8 * 320):]
        assert (np.abs(right.astype(int) - image[0, 0].astype(int)).sum(axis=2) > 100).mean() > 0.02  # bar drawn
    finally:
        plotter.close()


def test_decorations_switch_off_and_follow_the_transfer_function():
    plotter, controller = _scene(data_file("ecosystem/notch_disp.vtu"), scalar_bar=False, axes=False, outline=False)
    try:
        assert scalar_bar_actor(plotter) is None and OUTLINE_NAME not in plotter.renderer.actors
        assert plotter.renderer.axes_widget is None or not plotter.renderer.axes_widget.GetEnabled()
        controller.session.render.options["scalar_bar"] = True
        controller.decorate()
        bar = scalar_bar_actor(plotter)
        assert bar is not None and scalar_bar_title(plotter) == "Nodal Displacement (magnitude)"
        controller.set_transfer_function("data", controller.transfer_function("data").rescaled(0.0, 1e-6),
                                         update=False)
        assert scalar_bar_actor(plotter).GetLookupTable().GetRange() == pytest.approx((0.0, 1e-6))
    finally:
        plotter.close()
