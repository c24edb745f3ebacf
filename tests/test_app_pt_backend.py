"""The render setting Backend in the app (issue #16): a PT volume drawn on the GPU (``volviz.render.gl_pt``, VTK's
OpenGL with volviz's shaders) shows the image the CPU backend (``volviz.render.pt_prop``) shows, a camera drag
redraws it with no CPU render and no sort on the GUI thread (the visibility order is made by background jobs, the
draws in between reuse the newest one), and switching the setting rebuilds the volume on the other backend. Under
Xvfb with real widgets and real VTK rendering on llvmpipe.

Bound: RMSE <= 1 and max <= 4 of 255 between the two backends' viewport screenshots (the GL PT tests' bound against
the exact reference; the CPU image passes through an 8-bit straight-alpha overlay, the GPU's through a float
target). Measured here on the demo volume in a 900x650 window: RMSE 0.165, max 2 before the drag, 0.173 / 2 after
it and the switch back to the CPU.
"""
from __future__ import annotations

from typing import Any

import numpy as np
from PySide6.QtCore import QEvent, QPoint, QSignalBlocker, Qt

from test_app_workflows import _mouse, viewport, wait_loaded
from volviz.render.backend import plotter_gl_info
from volviz.render.gl import ScenePass
from volviz.render.gl_pt import GLPTVolume
from volviz.render.pt_prop import PTVolume
from volviz_app.window import MainWindow

RMSE, MAX = 1.0, 4.0


def _difference(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    d = a - b
    return float(np.sqrt((d ** 2).mean())), float(np.abs(d).max())


def _set_backend(qtbot, window: MainWindow, backend: str) -> Any:
    """Choose ``backend`` in the render settings dock, as a user does, the GPU pass in the scene's window ("GPU in a
    thread" off: as "auto" on a hardware OpenGL); returns the rebuilt demo volume once shown (a CPU volume once its
    full-size image is on screen)."""
    old = window.controller
    with QSignalBlocker(window.render_settings.gpu_thread):
        window.render_settings.gpu_thread.setCurrentText("off")
    window.render_settings.backend.setCurrentText(backend)
    qtbot.waitUntil(lambda: window.controller is not old, timeout=60000)
    wait_loaded(qtbot, window)
    volume = window.controller.props["demo"]
    if isinstance(volume, PTVolume):
        w, h = (int(v) for v in window.plotter.ren_win.GetSize())
        qtbot.waitUntil(lambda: volume.image is not None and volume.image.shape[:2] == (h, w)
                        and not window._view_jobs["pt:demo"].running, timeout=60000)
    return volume


def test_gpu_backend_matches_the_cpu_follows_a_drag_without_cpu_renders_and_switches_back(qtbot,
                                                                                         make_window) -> None:
    window = make_window()
    window.resize(900, 650)
    window.open_demo_volume()
    wait_loaded(qtbot, window)
    cpu = _set_backend(qtbot, window, "cpu")
    assert isinstance(cpu, PTVolume) and window.controller.pt_backends() == {"demo": "cpu"}
    cpu_image = viewport(window)

    gpu = _set_backend(qtbot, window, "gpu")
    assert isinstance(gpu, GLPTVolume) and window.session.render.options["backend"] == "gpu"
    assert window.controller.pt_volume("demo") is None  # nothing for the app's CPU scheduler
    gpu_image = viewport(window)
    gpu.visible = False
    hidden = viewport(window)
    gpu.visible = True
    assert np.abs(gpu_image - hidden).max() > 50, "the GPU volume is not on screen"
    e = _difference(gpu_image, cpu_image)
    assert e[0] <= RMSE and e[1] <= MAX, f"GPU vs CPU backend in the viewport: RMSE {e[0]:.3f}, max {e[1]:.0f}"
    window.render_scene()
    assert window.statistics.text("backends") == "demo: gpu"
    assert window.statistics.text("gl") == plotter_gl_info(window.plotter).renderer != ""

    # a mouse drag of the camera: VTK draws the volume at every repaint with the newest visibility order, which
    # background jobs make; no CPU render job is submitted and no render sorts on the GUI thread
    submitted: list[str] = []
    submit = window.jobs.submit

    def recorded(fn, *args, name: str, **kwargs):
        submitted.append(name)
        return submit(fn, *args, name=name, **kwargs)

    window.jobs.submit = recorded  # the real submit, recorded
    updates = dict(window.view_updates)
    start = np.asarray(gpu.camera.position, dtype=float).copy()
    canvas = window.plotter.interactor
    centre = QPoint(canvas.width() // 2, canvas.height() // 2)
    held = Qt.MouseButton.LeftButton
    _mouse(canvas, QEvent.Type.MouseButtonPress, centre, held)
    drawn: list[np.ndarray] = []
    sorted_here: list[bool] = []
    for k in range(1, 21):
        _mouse(canvas, QEvent.Type.MouseMove, centre + QPoint(5 * k, k), held)
        qtbot.wait(40)
        drawn.append(np.asarray(gpu.camera.position, dtype=float).copy())
        sorted_here.append(bool(gpu.stats["sorted"] and not gpu.stats["sort_prefetched"]))   # worker orders
    _mouse(canvas, QEvent.Type.MouseButtonRelease, centre + QPoint(100, 20), Qt.MouseButton.NoButton)
    qtbot.wait(300)
    # the order of the final camera arrives from its job and is drawn: exact again
    qtbot.waitUntil(lambda: not window._view_jobs["pt-order:demo"].running and gpu.stats["order_reused"] is False
                    and gpu._sorted_key is not None and np.allclose(gpu._sorted_key[0], gpu.camera.position),
                    timeout=30000)
    assert not any(sorted_here), "a render during the drag sorted on the GUI thread"
    assert "visibility order" in submitted
    final = np.asarray(window.plotter.camera.position, dtype=float)
    assert not np.allclose(final, start), "the drag did not move the camera"
    assert len({tuple(p) for p in drawn}) >= 3, "the volume was not redrawn while the camera moved"
    assert np.allclose(gpu.camera.position, final), "the last draw is not of the final camera"
    assert "volume" not in submitted and "error estimate" not in submitted, submitted
    assert window.view_updates.get("pt:demo") == updates.get("pt:demo")
    after_drag = viewport(window)
    assert np.allclose(gpu.camera.position, final)

    # gpu -> cpu at the dragged camera: the same image within the bound
    window.jobs.submit = submit
    cpu = _set_backend(qtbot, window, "cpu")
    assert isinstance(cpu, PTVolume) and np.allclose(cpu.camera.position, final)
    e = _difference(viewport(window), after_drag)
    assert e[0] <= RMSE and e[1] <= MAX, f"after switching gpu -> cpu: RMSE {e[0]:.3f}, max {e[1]:.0f}"
    window.render_scene()
    assert window.statistics.text("backends") == "demo: cpu"


def test_closing_the_window_frees_the_gpu_volume_before_its_context(qtbot, make_window) -> None:
    """The float target of the GPU pass is taken off the viewport's renderer (its GL resources released) when the
    window closes: left on, VTK reports at the renderer's destruction that its framebuffer was never deleted."""
    window = make_window()
    window.resize(600, 400)
    window.open_demo_volume()
    wait_loaded(qtbot, window)
    assert isinstance(_set_backend(qtbot, window, "gpu"), GLPTVolume)
    window.render_scene()
    renderer = window.plotter.renderer
    assert ScenePass.of(renderer) is not None
    window.dirty = False
    window.close()
    assert ScenePass.of(renderer) is None, "the float target outlived the window"
