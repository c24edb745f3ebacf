"""Screenshot export keeps the event loop live (issue #5, "Background work" and "Export screenshot"): the offscreen
scene is prepared and its volviz CPU images are rendered on a worker; only the VTK side (adding props, the final
offscreen render) runs on the GUI thread. Under Xvfb with real widgets and real rendering."""
from __future__ import annotations

import threading
from pathlib import Path

import imageio.v3 as iio
import numpy as np

from loop_latency import LoopGaps
from test_app_workflows import make_window, wait_loaded  # noqa: F401 (a fixture and a helper shared with it)


def test_screenshot_export_prepares_and_renders_in_the_background(qtbot, make_window, tmp_path: Path) -> None:
    window = make_window()
    window.resize(1000, 700)
    qtbot.wait(300)  # the viewport's resize handling is over
    window.open_demo()  # terrain, fog, clouds, sky and a PT tetrahedral volume: seconds of CPU work offscreen
    wait_loaded(qtbot, window)
    out = tmp_path / "shot.png"
    gaps = LoopGaps()
    # the final offscreen VTK render stays on this thread and grows with the pixels (the demo on llvmpipe: ~70 ms
    # at 320x200, ~100 ms at 640x400); everything else of the export runs on a worker
    window.export_screenshot(out, size=(320, 200))
    assert not out.exists(), "the screenshot was prepared and rendered on the GUI thread"
    assert window.progress_bar.isVisible() and window.cancel_button.isVisible()
    qtbot.waitUntil(lambda: window.screenshot_result is not None, timeout=120000)
    gaps.stop()
    assert window.screenshot_result is True
    assert window.screenshot_threads and threading.main_thread().ident not in window.screenshot_threads
    image = iio.imread(out)
    assert image.shape[:2] == (200, 320)
    assert image[..., :3].std() > 3.0
    print(gaps.summary())
    gaps.assert_responsive("during the export", 10)


def test_screenshot_export_can_be_cancelled(qtbot, make_window, tmp_path: Path) -> None:
    window = make_window()
    window.open_demo()
    wait_loaded(qtbot, window)
    out = tmp_path / "shot.png"
    window.export_screenshot(out, size=(320, 200))
    window.cancel_current_job()
    qtbot.waitUntil(lambda: window.screenshot_result is not None, timeout=120000)
    assert window.screenshot_result is False
    assert not out.exists()
    assert "cancelled" in window.status_label.text()
    assert not window.progress_bar.isVisible()
    window.export_screenshot(out, size=(320, 200))  # the app keeps working
    qtbot.waitUntil(lambda: window.screenshot_result is not None, timeout=120000)
    assert window.screenshot_result is True and iio.imread(out).shape[:2] == (200, 320)
    assert np.asarray(iio.imread(out))[..., :3].std() > 3.0
