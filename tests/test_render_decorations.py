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
    from volviz.render.offscreen import offscreen_plotter
    from volviz.scene.datasets import load_datasets
    from volviz.scene.opening import data_session

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


def test_scalar_bar_labels_a_symmetric_range_with_zero():
    """A field of either sign (warping_spheres: -6.98328 .. 6.98321): the middle label is 0, not -3.3e-05 (VTK's own
    labels printed "-3.34e-05", which ran off the right edge of a small window); the labels span the range; ranges
    of one sign, or narrow and far from zero, keep their values."""
    from volviz.render.decorations import label_values

    assert label_values(-6.98, 6.98).tolist() == [-6.98, -3.49, 0.0, 3.49, 6.98]
    assert label_values(-6.98328, 6.98321)[2] == 0.0
    assert label_values(-1.0, 3.0).tolist() == [-1.0, 0.0, 1.0, 2.0, 3.0]
    assert label_values(0.0, 1e-6).tolist() == pytest.approx([0.0, 2.5e-7, 5e-7, 7.5e-7, 1e-6])
    assert label_values(1000.0, 1000.004).tolist() == pytest.approx([1000.0, 1000.001, 1000.002, 1000.003, 1000.004])
    plotter, controller = _scene(data_file("series/warping_spheres.vtkhdf"))
    try:
        bar = scalar_bar_actor(plotter)
        lo, hi = bar.GetLookupTable().GetRange()
        assert lo < 0 < hi and bar.GetUseCustomLabels()
        labels = [bar.GetCustomLabels().GetValue(i) for i in range(bar.GetCustomLabels().GetNumberOfTuples())]
        assert labels[0] == lo and labels[-1] == hi and labels[2] == 0.0
    finally:
        plotter.close()


def test_scalar_bar_labels_are_short_enough_for_a_small_export(tmp_path):
    """Labels in fixed point with the decimals the label step needs ("-1000", not VTK's "-1.00e+03"), scientific
    only where that is shorter; at 320 x 240 the labels of a CT range (-1000 .. 1000 HU) stay inside the image: its
    last columns are background (with "%-#6.3g" the label "1.00e+03" ran over the right edge)."""
    from volviz.render.decorations import label_format, label_values

    def shown(lo, hi):
        fmt = label_format(lo, hi)
        return [fmt % v for v in label_values(lo, hi)]

    assert shown(-1000.0, 1000.0) == ["-1000", "-500", "0", "500", "1000"]
    assert shown(0.0, 1162.0) == ["0", "290", "581", "872", "1162"]
    assert shown(-6.98, 6.98) == ["-7.0", "-3.5", "0.0", "3.5", "7.0"]
    assert shown(0.0, 1.0) == ["0.00", "0.25", "0.50", "0.75", "1.00"]
    assert shown(0.0, 1e-6) == ["0.00e+00", "2.50e-07", "5.00e-07", "7.50e-07", "1.00e-06"]
    assert len(set(shown(1000.0, 1000.004))) == 5          # labels of a narrow range far from zero differ
    assert shown(5.0, 5.0) == ["5"] * 5

    ct = np.linspace(-1000.0, 1000.0, 16 * 16 * 16).reshape(16, 16, 16)
    np.save(tmp_path / "ct.npy", ct)
    plotter, controller = _scene(tmp_path / "ct.npy", axes=False, outline=False)
    try:
        assert scalar_bar_actor(plotter).GetLabelFormat() == "%.0f"
        image = np.asarray(plotter.screenshot(None, return_img=True)).astype(int)
        edge = image[:, -3:]
        assert (np.abs(edge - image[0, 0]).sum(axis=-1) > 60).sum() == 0    # nothing drawn over the right edge
        labels = image[:, int(0.86 * 320):]
        assert (np.abs(labels - image[0, 0]).sum(axis=-1) > 60).mean() > 0.01   # the labels are drawn
    finally:
        plotter.close()
