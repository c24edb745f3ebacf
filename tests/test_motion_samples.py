"""Multisampling is off while the camera moves on a software OpenGL and back for the still frame
(``volviz.render.motion_samples``), and it shares the single-sample hold with the overlays."""
from __future__ import annotations

import numpy as np
import pyvista as pv

from volviz.render.backend import plotter_gl_info
from volviz.render.image_overlay import hold_single_sample, release_single_sample
from volviz.render.motion_samples import SingleSampleWhileMoving
from volviz.render.offscreen import offscreen_plotter


def _plotter() -> pv.Plotter:
    plotter = offscreen_plotter((96, 64))
    plotter.ren_win.SetMultiSamples(4)
    plotter.add_mesh(pv.Sphere(), color="white")
    plotter.render()
    return plotter


def test_off_while_moving_on_a_software_driver_and_the_still_frame_is_unchanged() -> None:
    plotter = _plotter()
    try:
        assert plotter_gl_info(plotter).software            # llvmpipe here
        still = np.asarray(plotter.screenshot(None, return_img=True), dtype=np.int16)
        motion = SingleSampleWhileMoving(plotter)
        motion.moving()
        motion.moving()                                      # a motion going on holds once
        assert plotter.ren_win.GetMultiSamples() == 0
        plotter.render()
        moving = np.asarray(plotter.screenshot(None, return_img=True), dtype=np.int16)
        assert np.abs(moving - still).max() > 0             # the sphere's edge is aliased while moving
        motion.stopped()
        assert plotter.ren_win.GetMultiSamples() == 4
        plotter.render()
        again = np.asarray(plotter.screenshot(None, return_img=True), dtype=np.int16)
        assert np.array_equal(again, still)                  # the still frame after the motion is the one before
        motion.stopped()                                     # stopping twice changes nothing
        assert plotter.ren_win.GetMultiSamples() == 4
    finally:
        plotter.close()


def test_a_hardware_driver_keeps_its_multisampling() -> None:
    plotter = _plotter()
    try:
        motion = SingleSampleWhileMoving(plotter, software=False)
        motion.moving()
        assert plotter.ren_win.GetMultiSamples() == 4 and not motion.held
    finally:
        plotter.close()


def test_an_overlay_keeps_single_sampling_after_the_motion() -> None:
    plotter = _plotter()
    try:
        motion = SingleSampleWhileMoving(plotter)
        motion.moving()
        overlay = object()
        hold_single_sample(plotter, overlay)                 # e.g. a PT overlay added while the camera moves
        motion.stopped()
        assert plotter.ren_win.GetMultiSamples() == 0        # the overlay still needs one sample per pixel
        release_single_sample(plotter, overlay)
        assert plotter.ren_win.GetMultiSamples() == 4
    finally:
        plotter.close()
