"""Fly mode stops short of opaque geometry (volviz.render.collision with FlyNavigator.obstacle): the eye keeps its
clearance from a sphere it flies at, moves away freely, and ignores translucent, hidden and decoration actors."""
from __future__ import annotations

import numpy as np
import pytest
import pyvista as pv

from volviz.render.camera_path import FlyNavigator
from volviz.render.collision import DEFAULT_CLEARANCE, OpaqueObstacles, fly_clearance
from volviz.session import CameraState


@pytest.fixture()
def plotter():
    p = pv.Plotter(off_screen=True)
    yield p
    p.close()


def test_flight_stops_the_clearance_short_of_an_opaque_surface(plotter):
    plotter.add_mesh(pv.Sphere(radius=1.0, theta_resolution=64, phi_resolution=64))
    obstacles = OpaqueObstacles(plotter.renderer)
    hit = obstacles(np.array([-5.0, 0.0, 0.0]), np.array([5.0, 0.0, 0.0]))
    assert hit == pytest.approx(4.0, abs=2e-3)                     # the sphere's surface at x = -1
    nav = FlyNavigator(speed=10.0, clearance=0.1, obstacle=obstacles)
    cam = CameraState(position=(-5.0, 0.0, 0.0), focal_point=(0.0, 0.0, 0.0))
    stopped = nav.move(cam, forward=1.0, dt=1.0)                   # 10 units asked, 3.9 allowed
    assert stopped.position[0] == pytest.approx(-1.1, abs=2e-3)
    assert nav.move(stopped, forward=1.0, dt=1.0).position == pytest.approx(stopped.position)   # no further
    back = nav.move(stopped, forward=-1.0, dt=0.1)                 # away from the surface: free
    assert back.position[0] == pytest.approx(stopped.position[0] - 1.0)
    side = nav.move(stopped, right=1.0, dt=0.05)                   # along it: free while nothing is in the way
    assert np.linalg.norm(np.subtract(side.position, stopped.position)) == pytest.approx(0.5)


def test_translucent_hidden_and_decoration_actors_are_no_obstacles(plotter):
    plotter.add_mesh(pv.Sphere(radius=1.0), opacity=0.5)
    hidden = plotter.add_mesh(pv.Sphere(radius=2.0))
    hidden.SetVisibility(False)
    plotter.add_mesh(pv.Box((-3, 3, -3, 3, -3, 3)).outline(), name="volviz-outline")
    obstacles = OpaqueObstacles(plotter.renderer)
    assert obstacles(np.array([-5.0, 0.0, 0.0]), np.array([5.0, 0.0, 0.0])) is None
    hidden.SetVisibility(True)                                      # the locator follows the change
    assert obstacles(np.array([-5.0, 0.0, 0.0]), np.array([5.0, 0.0, 0.0])) == pytest.approx(3.0, abs=0.05)


def test_clearance_is_a_render_option():
    assert fly_clearance({}) == DEFAULT_CLEARANCE
    assert fly_clearance({"fly_clearance": 0.05}) == 0.05
    for bad in (-1, 0.9, "x", True):
        assert fly_clearance({"fly_clearance": bad}) == DEFAULT_CLEARANCE
