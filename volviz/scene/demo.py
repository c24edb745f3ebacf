"""The built-in demo scenes as sessions with no datasets: the procedural natural scene
(``volviz.nature.nature_scene.demo_scene``) written as session components, and the analytic tetrahedral cube."""
from __future__ import annotations

from volviz.session import CameraState, Component, RenderSettings, Session


def demo_components() -> list[Component]:
    """Session components of the procedural natural scene (no datasets): fractal terrain, Perlin ground fog, Perlin
    clouds, sky gradient — what ``demo_scene`` builds, for a session or the app's default scene."""
    return [
        Component(id="terrain", type="terrain", settings={"size": 257, "seed": 1, "relief": 160.0,
                                                          "extent": [1000.0, 1000.0], "C": 9.0, "c": 40.0}),
        Component(id="ground_fog", type="fog", settings={"level": 55.0, "thickness": 25.0, "seed": 2,
                                                         "mode": "attenuated", "density": 0.04,
                                                         "color": [0.85, 0.87, 0.95]}),
        Component(id="clouds", type="clouds", settings={"shape": [129, 129, 17], "seed": 3, "coverage": 0.25,
                                                        "base_height": 190.0, "rho_max": 0.06}),
        Component(id="sky", type="sky"),
    ]


def demo_session() -> Session:
    """The built-in procedural natural scene (fractal terrain, Perlin ground fog and clouds, sky), generated at
    start-up from no files."""
    camera = CameraState(position=(500.0, -150.0, 330.0), focal_point=(500.0, 600.0, 80.0), view_up=(0.0, 0.0, 1.0),
                         view_angle=60.0)
    return Session(components=demo_components(), camera=camera,
                   render=RenderSettings(size=(1024, 768), background=(0.78, 0.85, 0.95)))


def demo_volume_session() -> Session:
    """A tetrahedralised cube carrying an analytic field (``volviz render demo-volume``)."""
    return Session(components=[Component(id="demo", type="demo", settings={"cells_per_edge": 20})])
