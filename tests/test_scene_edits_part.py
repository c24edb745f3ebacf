"""The scene edits are a part of the window given their collaborators (issue #31, the window composed, not mixed in):
``volviz_app.scene_edits.SceneEdits`` works beside a plain ``QMainWindow``, a dataclass shown scene
(``volviz_app.shown_scene.ShownScene``) with a real ``SceneController``, the real docks and job bridge, and a views
collaborator that records what it is asked (``ViewRefreshes``), without a ``MainWindow``: what it reads and writes of
the window is what it was given."""
from __future__ import annotations

import threading
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterator, Optional

import numpy as np
import pytest

pytest.importorskip("PySide6")

from PySide6.QtGui import QUndoStack  # noqa: E402
from PySide6.QtWidgets import QLabel, QMainWindow  # noqa: E402

from volviz.model import RegularVolume  # noqa: E402
from volviz.model.events import SceneChange  # noqa: E402
from volviz.session import CameraState, Component, DatasetRef, Session  # noqa: E402
from volviz_app.array_choice import ArrayChoice  # noqa: E402
from volviz_app.docks.scene_tree import SceneTree  # noqa: E402
from volviz_app.docks.tf_editor import TransferFunctionEditor  # noqa: E402
from volviz_app.scene_edits import SceneEdits  # noqa: E402
from volviz_app.workers import JobBridge  # noqa: E402


@dataclass
class Shown:
    """The shown scene (``ShownScene``)."""

    session: Session
    datasets: dict[str, Any]
    session_path: Optional[Path] = None
    controller: Any = None
    title: str = "ball"
    dirty: bool = False


@dataclass
class Views:
    """The views' refreshes (``ViewRefreshes``): what the edits asked of them."""

    last_error_rmse: Optional[float] = None
    followed: list[SceneChange] = field(default_factory=list)
    refreshed: list[Optional[list[str]]] = field(default_factory=list)
    renders: int = 0

    def views_follow(self, change: SceneChange) -> None:
        self.followed.append(change)

    def refresh_views(self, keys: Optional[list[str]] = None, settled: Optional[Callable[[], None]] = None,
                      scale: int = 1, estimate: bool = True, moving: bool = False) -> int:
        self.refreshed.append(keys)
        return 0

    def refresh_nature(self, settled: Optional[Callable[[], None]] = None, scale: int = 1) -> None:
        self.refreshed.append(["nature"])

    def schedule_render(self) -> None:
        self.renders += 1


@pytest.fixture
def part(qtbot) -> Iterator[tuple[SceneEdits, Shown, Views, dict[str, list[Any]]]]:
    import pyvista as pv

    from volviz.render.controller import SceneController

    g = np.linspace(-1.0, 1.0, 16)
    x, y, z = np.meshgrid(g, g, g, indexing="ij")
    ball = RegularVolume((x * x + y * y + z * z).astype(np.float32))
    session = Session(datasets=[DatasetRef("ball", "/unused")],
                      components=[Component("vol", "volume", "ball"),
                                  Component("later", "volume", "ball", visible=False)],
                      camera=CameraState((0.0, -6.0, 2.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    session.render.options.update(scalar_bar=False, axes=False, outline=False)
    window = QMainWindow()
    qtbot.addWidget(window)
    plotter = pv.Plotter(off_screen=True, window_size=[64, 48])
    shown = Shown(session, {"ball": ball})
    shown.controller = controller = SceneController(plotter, session, shown.datasets, on_screen=True)  # as the app's
    controller.build()
    views, calls = Views(), {"dirty": [], "errors": [], "shown": [], "budget": [], "rendered": []}
    tf_editor, tree, jobs = TransferFunctionEditor(), SceneTree(), JobBridge(window)
    edits = SceneEdits(shown, window, views, jobs, QLabel(), tf_editor, tree,
                       ArrayChoice(shown, tree.array, QUndoStack(window)),
                       render_scene=lambda: calls["rendered"].append(True),
                       set_dirty=lambda: calls["dirty"].append(True),
                       show_error=lambda title, text: calls["errors"].append((title, text)),
                       show_session=lambda *args: calls["shown"].append(args),
                       enforce_error_budget=calls["budget"].append)
    edits.scene_installed()
    controller.changes.subscribe(edits.scene_changed)
    tree.populate(session.components, ["ball"])
    try:
        yield edits, shown, views, calls
    finally:
        edits.stop()
        jobs.shutdown()
        controller.clear()
        plotter.close()


def test_the_docks_edits_reach_the_session_and_the_views_follow(qtbot, part) -> None:
    edits, shown, views, calls = part
    session = shown.session

    edits.set_opacity("vol", 0.25)
    assert shown.controller.component("vol").opacity == 0.25
    assert views.followed == [SceneChange("opacity", "vol")] and calls["dirty"] == [True]
    assert edits.scene_tree.item("vol").data(0, 257) == 0.25       # the tree shows the scene's opacity (UserRole+1)

    tf = shown.controller.transfer_function("vol").scaled_extinction(2.0)
    edits.tf_changed(tf)                                           # a drag: one edit of the session per PREVIEW_MS
    name = shown.controller.component("vol").transfer_function
    assert session.transfer_functions[name] != tf and edits.preview_timer.isActive()
    qtbot.waitUntil(lambda: session.transfer_functions[name] == tf, timeout=5000)
    assert views.followed[-1] == SceneChange("transfer_function", "vol", preview=True)
    edits.tf_editor.set_transfer_function(tf)                      # the editor's finished edit: drawn at full size
    edits.tf_committed(edits.tf_editor.committed_transfer_function)
    qtbot.waitUntil(lambda: views.followed[-1] == SceneChange("transfer_function", "vol"), timeout=5000)

    edits.set_clip({"planes": [{"point": [0, 0, 0], "normal": [0, 0, 0]}], "box": None})
    assert calls["errors"] and calls["errors"][0][0] == "Invalid clipping" and not session.clip.planes
    assert edits.clipping_shown()

    values = {"method": "pt", "size": list(session.render.size), "options": dict(session.render.options)}
    edits.settings_changed(values)                                 # another renderer: shown again, same camera
    assert session.render.method == "pt" and len(calls["shown"]) == 1
    again, path, title, dirty, datasets = calls["shown"][0]
    assert again is session and path is None and title == "ball" and dirty and datasets is shown.datasets
    assert session.camera == shown.controller.camera()
    assert not calls["budget"]


def test_a_hidden_component_gets_its_histogram_and_is_shown_in_the_background(qtbot, part) -> None:
    edits, shown, views, calls = part
    assert "later" not in shown.controller.histograms

    edits.scene_tree.tree.setCurrentItem(edits.scene_tree.item("later"))   # the editor shows the selected one
    edits.select_component("later")
    qtbot.waitUntil(lambda: edits.histograms_computed == 1, timeout=60000)
    assert threading.main_thread().ident not in edits.histogram_threads
    counts, edges = shown.controller.histograms["later"]
    assert int(np.sum(counts)) == 16 ** 3 and edges[0] == pytest.approx(0.0, abs=0.02) and edges[-1] == 3.0

    edits.set_visibility("later", True)
    qtbot.waitUntil(lambda: edits.components_shown == 1, timeout=60000)
    assert shown.controller.component("later").visible and not shown.controller.needs_build("later")
    assert views.renders >= 1 and ["later", "iso-overlay"] in views.refreshed
    assert SceneChange("visible", "later") in views.followed and not calls["errors"]
