"""The box a flying eye stays in (``volviz.render.collision.fly_bounds``, ``FlyNavigator.bounds``)."""
from __future__ import annotations

import numpy as np

from volviz.nature.heightfield import HeightField
from volviz.render.camera_path import CameraState, FlyNavigator
from volviz.render.collision import fly_bounds


def _terrain() -> HeightField:
    return HeightField(np.zeros((9, 9)) + np.arange(9.0)[:, None] * 1.25, spacing=(12.5, 12.5))


def test_terrain_box_holds_the_starting_eye_and_clamps_the_flight() -> None:
    terrain = _terrain()                      # 100 x 100, heights 0 .. 10 (9 x 9 points)
    box = fly_bounds(None, (50.0, -80.0, 30.0), terrain)
    assert box == (-50.0, 150.0, -80.0, 150.0, 0.0, 110.0)   # y grown to the eye at -80 (beyond the half extent)
    nav = FlyNavigator(speed=1000.0)
    nav.bounds = box
    cam = CameraState(position=(50.0, -80.0, 30.0), focal_point=(50.0, 0.0, 30.0), view_up=(0.0, 0.0, 1.0))
    ahead = nav.move(cam, forward=1.0, dt=1.0)                 # 1000 units forward: stops at the box
    assert ahead.position == (50.0, 150.0, 30.0)
    up = nav.move(cam, up=1.0, dt=1.0)
    assert up.position[2] == 110.0


def test_without_terrain_the_box_is_the_scene_grown_by_its_size() -> None:
    box = fly_bounds((0.0, 1.0, 0.0, 2.0, 0.0, 4.0), (0.5, 1.0, 2.0))
    assert box == (-4.0, 5.0, -4.0, 6.0, -4.0, 8.0)
