"""The demo scene as a new user first sees it (``volviz-app`` with no file), issue #28's "vertical seams in the clouds":
the frame on screen matches ``volviz render`` of the saved session at the same camera and size (the bounds of
``tests/test_flow_kinds.py``), and the clouds have no seam at the eye's plane x = 500 (a boundary of the clouds'
C-LOD roots), which the demo camera sees as the viewport's centre column (the seam metric of
``tests/test_cloud_seams.py``). Measured in a 1024x805 viewport (llvmpipe, CPU backend): the screen equals the
render (RMSE 0.00); the centre column's step 2.05x its neighbours' before the fix, 0.61x after."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from flows import compare_with_render, screen, wait_loaded, wait_settled
from test_cloud_seams import DEMO_EYE, DEMO_FOCUS, SEAM, seam_ratio
from volviz.model.camera import Camera
from volviz.nature.clouds import render_cloud_image

RMSE, OFF = 1.5, 0.005


def test_demo_clouds_on_screen_match_the_render_without_seams(qtbot, make_window, tmp_path: Path) -> None:
    window = make_window()
    window.open_demo()
    wait_loaded(qtbot, window)
    wait_settled(qtbot, window)
    shown = screen(window)
    if shown.shape[1] % 2:             # the centre between two columns: an even viewport width
        window.resize(window.width() + 1, window.height())
        wait_settled(qtbot, window)
        shown = screen(window)
    h, w = shown.shape[:2]
    assert w % 2 == 0
    err = compare_with_render(window, tmp_path, "demo")
    assert err["rmse"] < RMSE and err["off"] < OFF, err

    scene = window.controller.nature.scene
    cam = Camera(DEMO_EYE, DEMO_FOCUS, (0.0, 0.0, 1.0), 60.0, clipping_range=(5.0, 10000.0))
    alpha = render_cloud_image(scene.cloud_lod.update(cam, (w, h)), scene.cloud_shading, scene.cloud_table, cam,
                               (w, h))[..., 3]
    rows = np.flatnonzero(alpha.mean(axis=1) > 0.2)
    assert len(rows) > 50
    ratio = seam_ratio(shown, rows)
    print(f"viewport {w}x{h}: RMSE {err['rmse']:.2f} against volviz render, seam ratio {ratio:.2f}")
    assert ratio < SEAM
