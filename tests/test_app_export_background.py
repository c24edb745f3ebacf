"""Screenshot export keeps the event loop live (issue #5, "Background work" and "Export screenshot"): the offscreen
scene is prepared and its volviz CPU images are rendered on a worker; only the VTK side (adding props, the final
offscreen render) runs on the GUI thread. Under Xvfb with real widgets and real rendering."""
from __future__ import annotations

import threading
from pathlib import Path

import imageio.v3 as iio
import numpy as np

from loop_latency import LoopGaps
from test_app_workflows import wait_loaded  # a helper shared with it (the make_window fixture is in conftest.py)


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
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=120000)
    gaps.stop()
    assert window.export_result is True
    assert window.export_threads and threading.main_thread().ident not in window.export_threads
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
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=120000)
    assert window.export_result is False
    assert not out.exists()
    assert "cancelled" in window.status_label.text()
    assert not window.progress_bar.isVisible()
    window.export_screenshot(out, size=(320, 200))  # the app keeps working
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=120000)
    assert window.export_result is True and iio.imread(out).shape[:2] == (200, 320)
    assert np.asarray(iio.imread(out))[..., :3].std() > 3.0


def test_movie_through_time_is_exported_in_the_background_and_cancel_leaves_no_partial_file(
        qtbot, make_window, tmp_path: Path) -> None:
    """A movie through a time series (the storm's isosurfaces, re-extracted for every frame) renders like a
    screenshot: the isosurfaces, views and encoding on workers, only the VTK side here, the event loop live and the
    app usable meanwhile; a cancelled MP4 leaves nothing behind."""
    from test_app_background import storm_iso_session

    window = make_window()
    window.resize(1000, 700)
    qtbot.wait(300)
    window.open_path(storm_iso_session(tmp_path))
    wait_loaded(qtbot, window)
    frames = tmp_path / "frames"
    gaps = LoopGaps()
    window.export_movie(frames, None, through_time=True, fps=0.5, size=(160, 120))
    assert not frames.exists() or not list(frames.iterdir()), "frames were rendered on the GUI thread"
    assert window.progress_bar.isVisible() and window.cancel_button.isVisible()
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=300000)
    gaps.stop()
    assert window.export_result is True, window.status_label.text()
    assert window.export_threads and threading.main_thread().ident not in window.export_threads
    pngs = sorted(frames.glob("frame_*.png"))
    span = window.controller.time_span()
    assert len(pngs) == int(round((span[1] - span[0]) * 0.5)) + 1  # a frame per 2 units of time, both ends
    images = [iio.imread(p)[..., :3].astype(int) for p in pngs]
    assert all(image.shape == (120, 160, 3) for image in images)
    changed = [np.abs(a - b).mean() for a, b in zip(images, images[1:])]
    assert min(changed) > 0.0, "a frame repeated the one before: the isosurfaces did not follow the time"
    assert "Exported frames" in window.status_label.text() and not window.progress_bar.isVisible()
    print(gaps.summary())
    gaps.assert_responsive("during a movie export", 50)

    movie = tmp_path / "storm.mp4"
    window.export_movie(movie, None, through_time=True, fps=0.5, size=(160, 120))
    qtbot.waitUntil(lambda: "frame 3 of" in window.status_label.text(), timeout=120000)
    window.cancel_current_job()
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=120000)
    assert window.export_result is False and "cancelled" in window.status_label.text()
    assert [p.name for p in tmp_path.iterdir() if ".mp4" in p.name] == [], "a partial movie was left behind"
    assert not window.progress_bar.isVisible()
    window.export_movie(movie, None, through_time=True, fps=0.5, size=(160, 120))  # the app keeps working
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=300000)
    assert window.export_result is True
    video = iio.imread(movie, index=None)
    assert video.shape[0] == len(pngs) and video.shape[1:3] == (120, 160)
    assert [p.name for p in tmp_path.iterdir() if ".mp4" in p.name] == ["storm.mp4"]


def test_a_failed_export_reports_the_file_and_the_app_keeps_working(qtbot, make_window, tmp_path: Path) -> None:
    window = make_window()
    window.open_demo_volume()
    wait_loaded(qtbot, window)
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("a file where the PNG sequence's folder should go")
    window.export_movie(blocker / "frames", None, through_time=False, fps=1.0, size=(64, 48))
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=120000)
    assert window.export_result is False
    assert window.error_dialog is not None and window.error_dialog.isVisible()
    text = window.error_dialog.text()
    assert text.startswith("Could not export frames:") and "not-a-folder" in text, text
    assert window.status_label.text().startswith("Could not export frames")
    assert not window.progress_bar.isVisible()
    window.error_dialog.close()
    out = tmp_path / "after.png"
    window.export_screenshot(out, size=(64, 48))  # the app keeps working
    qtbot.waitUntil(lambda: window.export_result is not None, timeout=120000)
    assert window.export_result is True and iio.imread(out).shape[:2] == (48, 64)


def test_closing_the_window_during_a_movie_export_leaves_no_partial_movie(qtbot, make_window, tmp_path: Path) -> None:
    from test_app_background import storm_iso_session

    window = make_window()
    window.open_path(storm_iso_session(tmp_path))
    wait_loaded(qtbot, window)
    movie = tmp_path / "storm.mp4"
    window.export_movie(movie, None, through_time=True, fps=0.5, size=(160, 120))
    # ffmpeg creates the file once its encoder has a few frames
    qtbot.waitUntil(lambda: any(".mp4" in p.name for p in tmp_path.iterdir()), timeout=120000)
    assert window.export_result is None
    window.dirty = False
    window.close()
    # at once: the window is gone, so nothing later would clean up after it
    assert [p.name for p in tmp_path.iterdir() if ".mp4" in p.name] == [], "a partial movie was left behind"
    assert window.export_result is None  # abandoned, not reported to the closed window
    qtbot.wait(500)                      # late timers and job completions find the export over
    assert window.export_result is None and window.error_dialog is None
