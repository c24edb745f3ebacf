"""The view scheduler is a part of the window given its collaborators (issue #31, the window composed, not mixed in):
``volviz_app.view_scheduler.ViewScheduler`` works beside a plain ``QMainWindow`` with a real on-screen viewport
(pyvistaqt's ``QtInteractor``), a dataclass shown scene (``volviz_app.shown_scene.ShownScene``) holding a real
``SceneController`` of the tetrahedral demo volume on the CPU PT backend, the real render settings dock,
job bridge and stand-in frame, and recording callbacks, without a ``MainWindow``: what it reads and writes of the
window is what it was given."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Iterator

import pytest

pytest.importorskip("PySide6")

from PySide6.QtWidgets import QLabel, QMainWindow  # noqa: E402

from volviz.render.error_budget import MOST_ACCURATE_TABLE  # noqa: E402
from volviz.scene.demo import demo_volume_session  # noqa: E402
from volviz_app.docks.render_settings import RenderSettingsDock  # noqa: E402
from volviz_app.gc_guard import GuiThreadCollector  # noqa: E402
from volviz_app.navigation import FlyMode  # noqa: E402
from volviz_app.stand_in import StandInFrame  # noqa: E402
from volviz_app.view_scheduler import MOVING_SCALE, ViewScheduler  # noqa: E402
from volviz_app.workers import JobBridge  # noqa: E402

from test_scene_edits_part import Shown  # noqa: E402 - the shown scene (``ShownScene``) as a dataclass


@dataclass
class Part:
    scheduler: ViewScheduler
    shown: Shown
    plotter: Any
    status: QLabel
    calls: dict[str, list[Any]]
    serial: list[int]

    def size(self) -> tuple[int, int]:
        """The viewport's (height, width): what a full-size image of the PT volume has."""
        w, h = (int(v) for v in self.plotter.ren_win.GetSize())
        return h, w


@pytest.fixture
def part(qtbot) -> Iterator[Part]:
    from pyvistaqt import QtInteractor

    from volviz.render.controller import SceneController

    window = QMainWindow()
    qtbot.addWidget(window)
    plotter = QtInteractor(window, auto_update=False)
    window.setCentralWidget(plotter.interactor)
    window.resize(240, 180)
    window.show()
    qtbot.waitExposed(window)
    session = demo_volume_session()
    session.components[0].settings["cells_per_edge"] = 6
    session.render.options.update(backend="cpu", scalar_bar=False, axes=False, outline=False)
    shown = Shown(session, {}, title="demo")
    shown.controller = controller = SceneController(plotter, session, shown.datasets, on_screen=True)  # as the app's
    controller.build()
    calls: dict[str, list[Any]] = {k: [] for k in ("rendered", "stats", "errors", "busy", "settings", "nonfinite")}
    serial, status, jobs = [1], QLabel(), JobBridge(window)
    scheduler = ViewScheduler(
        shown, window, plotter, jobs, status, RenderSettingsDock(), StandInFrame(plotter),
        GuiThreadCollector(window), render_scene=lambda: calls["rendered"].append(True),
        show_statistics=lambda: calls["stats"].append(True),
        show_error=lambda title, text: calls["errors"].append((title, text)), set_busy=calls["busy"].append,
        settings_changed=calls["settings"].append, load_serial=lambda: serial[0],
        report_nonfinite=calls["nonfinite"].append)
    scheduler.watch_viewport(FlyMode(plotter, on_camera_moved=scheduler.fly_moved))
    try:
        yield Part(scheduler, shown, plotter, status, calls, serial)
    finally:
        jobs.shutdown()
        controller.clear()
        plotter.close()


def _idle(part: Part, key: str = "pt:demo") -> bool:
    job = part.scheduler.view_jobs.get(key)
    return job is not None and not job.running


def test_first_views_end_the_loading_with_an_error_estimate_and_the_budget(qtbot, part: Part) -> None:
    views, volume = part.scheduler, part.shown.controller.pt_volume("demo")
    part.shown.session.render.options["error_budget"] = 1e-6   # no CPU table meets it
    views.show_first_views(part.shown.controller, 1, "demo")
    assert views.loading_views
    qtbot.waitUntil(lambda: part.calls["busy"] == [False], timeout=60000)
    assert not views.loading_views and part.calls["nonfinite"] == ["demo"]
    assert views.view_updates == {"pt:demo": 1} and volume.image.shape[:2] == part.size()
    assert views.view_shown["pt:demo"]["preview"] is False and part.calls["stats"] == [True]
    assert part.status.text() == "Showing demo" and not part.calls["errors"]
    # the full-size image's error, measured in the background against the exact reference, and the budget applied
    qtbot.waitUntil(lambda: views.last_error_rmse is not None, timeout=60000)
    assert views.error_estimate.startswith(f"RMSE {views.last_error_rmse:.2f}, max ")
    assert views.last_error_rmse > 1e-6 and part.calls["rendered"] == [True]
    assert len(part.calls["settings"]) == 1
    assert {k: part.calls["settings"][0]["options"][k] for k in MOST_ACCURATE_TABLE} == MOST_ACCURATE_TABLE
    assert part.status.text().startswith(f"Measured error {views.last_error_rmse:.2f} exceeds the budget")
    views.scene_installed()   # another scene: nothing of it measured yet
    assert views.error_estimate is None and views.last_error_rmse is None


def test_an_older_loads_first_views_do_not_end_a_newer_loading(qtbot, part: Part) -> None:
    views = part.scheduler
    part.serial[0] = 2    # a newer open started after this scene's
    views.show_first_views(part.shown.controller, 1, "demo")
    qtbot.waitUntil(lambda: views.view_updates.get("pt:demo") == 1 and _idle(part), timeout=60000)
    assert views.loading_views and part.calls["busy"] == [] and part.calls["nonfinite"] == []
    views.supersede()
    assert not views.loading_views


def test_a_moving_camera_gets_previews_then_the_full_size_image(qtbot, part: Part) -> None:
    views, volume = part.scheduler, part.shown.controller.pt_volume("demo")
    h, w = part.size()
    views.camera_moving()
    qtbot.waitUntil(lambda: views.view_updates.get("pt:demo") == 1 and _idle(part), timeout=60000)
    assert volume.image.shape[:2] == (h // MOVING_SCALE, w // MOVING_SCALE)
    assert views.view_shown["pt:demo"]["preview"] is True and part.calls["stats"] == []   # no statistics of previews
    views.camera_moved()
    qtbot.waitUntil(lambda: views.view_updates.get("pt:demo") == 2 and _idle(part), timeout=60000)
    assert volume.image.shape[:2] == (h, w) and part.calls["rendered"] and part.calls["stats"] == [True]
    assert views.view_shown["pt:demo"]["preview"] is False and not part.calls["errors"]
    assert views.refresh_views(["no-such-view"]) == 0 and views.refresh_views(["demo"]) == 1
