"""The isosurfaces' transparency modes on the GPU backend in the app (issue #17): a session with semi-transparent
isosurfaces in a mode of the libMini note §4 and the render setting Backend on "gpu" shows them as a
``volviz.render.gl_iso.GLIsoView`` (passes of VTK actors drawn at every render): no CPU overlay job is submitted,
not for the scene, a camera change or a resize; the viewport matches the CPU compositor of the same mode; switching
the Backend to "cpu" rebuilds the scene with the CPU overlay and keeps the image. Under Xvfb with real widgets and VTK
rendering on llvmpipe.

Bounds, in 8-bit units of RGB over the viewport (the ball session of ``tests/test_app_clipping.py``, 3-pass): RMSE
<= 0.8 and at most 0.1 % of the pixels over 3 between the GPU viewport and the CPU compositor, and between the two
backends' viewports. Measured here (1166x618 viewport): RMSE 0.51 and no pixel over 3 against the compositor, RMSE 0.36
and none over 3 between the backends.
"""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np
from test_app_clipping import STYLES, open_session, session_file  # noqa: F401  (the fixture)
from test_app_workflows import viewport, wait_loaded

from volviz.iso.composite import render
from volviz.render.gl_iso import GLIsoView
from volviz.render.iso_overlay import IsoOverlay
from volviz.model.camera import Camera
from volviz_app.window import MainWindow

RMSE, SHARE = 0.8, 0.001


def _check(a: np.ndarray, b: np.ndarray, label: str) -> None:
    d = np.abs(a - b)[..., :3].max(axis=2)
    rmse = float(np.sqrt(((a - b)[..., :3] ** 2).mean()))
    over = int((d > 3).sum())
    print(label, f"RMSE {rmse:.3f}, max {d.max():.0f}, pixels over 3: {over} of {d.size}")
    assert rmse <= RMSE and over <= SHARE * d.size, (label, rmse, over)


def _cpu_expected(window: MainWindow, meshes: list[Any]) -> np.ndarray:
    w, h = window.plotter.ren_win.GetSize()
    cam = Camera.from_pyvista(window.plotter.renderer.GetActiveCamera())
    cpu, _ = render(meshes, cam, (w, h), "3pass")
    bg = np.asarray(window.session.render.background)
    return np.clip(cpu[..., :3] + (1.0 - cpu[..., 3:4]) * bg, 0.0, 1.0) * 255.0


def test_isosurfaces_on_the_gpu_backend_match_the_cpu_without_overlay_jobs(qtbot, make_window,
                                                                          session_file: Path) -> None:  # noqa: F811
    doc = json.loads(session_file.read_text())
    doc["render"]["options"].update(backend="gpu", iso_mode="3pass")
    session_file.write_text(json.dumps(doc))
    window = make_window()
    for dock in (window.tf_dock, window.stats_dock, window.clip_dock):
        dock.hide()                              # room for the whole scene in the viewport
    open_session(qtbot, window, session_file)
    controller = window.controller
    view = controller.iso_view
    assert isinstance(view, GLIsoView) and controller.iso_overlay is None and view.mode == "3pass"
    assert view.surfaces is not None and [m.style.opacity for m in view.meshes] == [0.5, 0.4]
    window.plotter.renderer.GetActiveCamera().Azimuth(20.0)   # a drag, its end and a resize: VTK redraws the passes
    window._camera_moving()
    window._camera_moved()
    window.resize(1300, 850)
    qtbot.wait(200)
    wait_loaded(qtbot, window)
    # no CPU overlay job was asked for (``_refresh_overlay`` keeps one queue per overlay) or finished
    assert "iso-overlay" not in window._view_jobs and "iso-overlay" not in window.view_updates
    gpu = viewport(window)
    _check(gpu, _cpu_expected(window, view.meshes), "gpu vs cpu compositor")
    window.render_scene()
    n = sum(m.n_triangles for m in view.meshes)
    assert window.last_stats["iso"].startswith(f"iso 3pass (gpu): {n:,} triangles, {2 * n:,} drawn, ")

    window.render_settings.backend.setCurrentText("cpu")
    qtbot.waitUntil(lambda: window.controller is not controller, timeout=60000)
    wait_loaded(qtbot, window)
    overlay = window.controller.iso_overlay
    assert isinstance(overlay, IsoOverlay) and window.controller.iso_view is overlay
    assert view.surfaces is None                                     # the GL passes left with the old scene
    size = tuple(window.plotter.ren_win.GetSize())
    qtbot.waitUntil(lambda: overlay.stats.get("method") == "iso 3pass" and overlay.stats.get("size") == size,
                    timeout=30000)
    _check(viewport(window), gpu, "cpu backend vs gpu")
