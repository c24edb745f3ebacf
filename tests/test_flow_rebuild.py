"""Changing the renderer rebuilds the scene in the background; the viewport never goes blank meanwhile (issue #28:
the Blunt Fin's volume was gone for 1.4 s)."""
from __future__ import annotations

import numpy as np

from conftest import data_file
from flows import compare_with_render, pick_combo_item, wait_loaded, wait_settled


def _volume_share(img: np.ndarray, background: np.ndarray) -> float:
    """The share of the viewport whose color is off the background by more than 24 levels."""
    return float((np.abs(img - background).max(axis=2) > 24).mean())


def test_changing_the_renderer_keeps_the_picture_until_the_new_one_is_shown(qtbot, make_window, tmp_path) -> None:
    window = make_window()
    window.open_path(data_file("bluntfin/bluntfinxyz.bin"))
    wait_loaded(qtbot, window)
    pick_combo_item(qtbot, window.render_settings.method, "vtk")   # VTK's mapper draws at once; volviz's PT later
    qtbot.waitUntil(lambda: window.session.render.method == "vtk", timeout=60000)
    wait_settled(qtbot, window)
    window.plotter.render()
    before = np.asarray(window.plotter.screenshot(None, return_img=True))[..., :3].astype(float)
    background = before[2, 2]
    shown = _volume_share(before, background)
    assert shown > 0.05
    other = "pt"
    pick_combo_item(qtbot, window.render_settings.method, other)
    shares, stand_in = [], False
    while window.progress_bar.isVisible() or window.jobs.busy() or not shares:
        qtbot.wait(50)
        stand_in = stand_in or window.stand_in.shown
        window.plotter.render()
        frame = np.asarray(window.plotter.screenshot(None, return_img=True))[..., :3].astype(float)
        shares.append(_volume_share(frame, background))
    wait_settled(qtbot, window)
    assert window.session.render.method == other and not window.stand_in.shown
    assert stand_in, "the rebuild was not covered by the last frame"
    assert min(shares) > 0.5 * shown, shares     # never blank while the new renderer's first image is made
    err = compare_with_render(window, tmp_path)
    assert err["rmse"] < 1.5 and err["off"] < 0.005, err
