"""The built-in demo scene as a session: the procedural natural scene (``volviz.nature.nature_scene.demo_scene``)
written as session components, with no datasets."""
from __future__ import annotations

from volviz.session import Component


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
