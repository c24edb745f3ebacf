"""The scene tree's Kind column says how a data file's component is drawn (real window under Xvfb): a point table
as "Points", a surface mesh as "Surface", a volume as "Volume" — not "Volume" for all three (the component type)."""
from __future__ import annotations

import numpy as np
import pyvista as pv

from test_app_workflows import wait_loaded


def test_kind_column_names_how_the_data_is_drawn(qtbot, make_window, tmp_path) -> None:
    (tmp_path / "probes.csv").write_text("x,y,z,t\n" + "\n".join(f"{i},{i % 3},{i % 5},{i * 0.5}" for i in range(30)))
    pv.Sphere().save(tmp_path / "shell.stl")
    grid = pv.ImageData(dimensions=(6, 5, 4))
    grid.point_data["density"] = np.arange(grid.n_points, dtype=np.float32)
    grid.save(tmp_path / "block.vti")
    window = make_window()
    window.resize(720, 540)
    for name, kind in (("probes.csv", "Points"), ("shell.stl", "Surface"), ("block.vti", "Volume")):
        window.open_path(tmp_path / name)
        qtbot.waitUntil(lambda name=name: getattr(window, "title", None) == name, timeout=60000)
        wait_loaded(qtbot, window)
        item = window.scene_tree.tree.topLevelItem(0)
        assert (item.text(0), item.text(1)) == ("data", kind), name
