"""The main window: a PyVista viewport, File menu, status bar with progress and cancel. No numerics here."""
from __future__ import annotations

import logging
import os
from pathlib import Path
from typing import Any, Optional

from PySide6.QtCore import QByteArray, Qt
from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import (QFileDialog, QLabel, QMainWindow, QMessageBox, QProgressBar, QPushButton, QWidget)

from volviz.jobs import JobOutcome
from volviz.session import Session, SessionError, relative_path
from volviz_app.workers import JobBridge

log = logging.getLogger(__name__)


def _data_filter() -> str:
    from volviz.io import supported_formats

    patterns = " ".join(f"*{ext}" for ext in supported_formats())
    return f"Data files ({patterns});;All files (*)"


class MainWindow(QMainWindow):
    """volviz main window. ``open_path`` is the single code path behind File > Open and the command line."""

    def __init__(self, parent: Optional[QWidget] = None):
        super().__init__(parent)
        from pyvistaqt import QtInteractor

        self.setWindowTitle("volviz")
        self.resize(1200, 800)
        self.plotter = QtInteractor(self)
        self.setCentralWidget(self.plotter.interactor)
        self.jobs = JobBridge(self)
        self.jobs.progress.connect(self._on_progress)
        self.session: Session = Session()
        self.session_path: Optional[Path] = None
        self.datasets: dict[str, Any] = {}
        self.error_dialog: Optional[QMessageBox] = None
        self._current_job = None
        self._build_menus()
        self._build_status_bar()

    # ------------------------------------------------------------------------------------------------ construction
    def _build_menus(self) -> None:
        file_menu = self.menuBar().addMenu("&File")
        self.action_open_data = self._action(file_menu, "Open &Data…", QKeySequence.StandardKey.Open,
                                             self._ask_open_data)
        self.action_open_session = self._action(file_menu, "Open &Session…", "Ctrl+Shift+O", self._ask_open_session)
        self.action_save_session = self._action(file_menu, "&Save Session", QKeySequence.StandardKey.Save,
                                                self._save_session)
        self.action_save_session_as = self._action(file_menu, "Save Session &As…", QKeySequence.StandardKey.SaveAs,
                                                   self._ask_save_session_as)
        file_menu.addSeparator()
        self.action_export_screenshot = self._action(file_menu, "&Export Screenshot…", "Ctrl+E",
                                                     self._ask_export_screenshot)
        file_menu.addSeparator()
        self._action(file_menu, "&Quit", QKeySequence.StandardKey.Quit, self.close)

    def _action(self, menu: Any, text: str, shortcut: Any, slot: Any) -> QAction:
        action = QAction(text, self)
        action.setShortcut(QKeySequence(shortcut))
        action.triggered.connect(slot)
        menu.addAction(action)
        return action

    def _build_status_bar(self) -> None:
        bar = self.statusBar()
        self.status_label = QLabel("Ready")
        self.progress_bar = QProgressBar()
        self.progress_bar.setMaximumWidth(220)
        self.progress_bar.setRange(0, 1000)
        self.cancel_button = QPushButton("Cancel")
        self.cancel_button.clicked.connect(self.cancel_current_job)
        bar.addWidget(self.status_label, 1)
        bar.addPermanentWidget(self.progress_bar)
        bar.addPermanentWidget(self.cancel_button)
        self._set_busy(False)

    # ------------------------------------------------------------------------------------------------ opening
    def open_demo(self) -> None:
        from volviz.render.scene import demo_session

        self._show_session(demo_session(), None, "demo scene")

    def open_path(self, path: str | os.PathLike) -> None:
        """Open a session file or a data file (the path behind every Open action and the command line)."""
        from volviz.render.export import is_session_file
        from volviz.render.scene import data_session
        from volviz.session import load

        p = Path(path)
        if not p.exists():
            self.show_error("Cannot open", f"{p}: no such file")
            return
        if is_session_file(p):
            try:
                session = load(p)
            except SessionError as exc:
                self.show_error("Cannot open session", str(exc))
                return
            self._show_session(session, p, p.name)
        else:
            self._show_session(data_session(p), None, p.name)

    def _show_session(self, session: Session, session_path: Optional[Path], title: str) -> None:
        from volviz.render.scene import load_datasets

        self.status_label.setText(f"Loading {title}…")
        self._set_busy(True)

        def done(outcome: JobOutcome) -> None:
            self._set_busy(False)
            if outcome.cancelled:
                self.status_label.setText(f"Loading {title} cancelled")
                return
            if outcome.error is not None:
                self.status_label.setText(f"Could not load {title}")
                self.show_error(f"Cannot open {title}", str(outcome.error))
                return
            self._install_session(session, session_path, outcome.result, title)

        self._current_job = self.jobs.submit(load_datasets, session, session_path, name=f"load {title}", key="load",
                                             on_done=done)

    def _install_session(self, session: Session, session_path: Optional[Path], datasets: dict[str, Any],
                         title: str) -> None:
        from volviz.render.scene import build_scene

        self.plotter.clear()
        try:
            build_scene(self.plotter, session, datasets)
        except Exception as exc:  # a scene that cannot be shown must not take the window down
            log.exception("building the scene for %s failed", title)
            self.show_error(f"Cannot show {title}", str(exc))
            return
        self.session, self.session_path, self.datasets = session, session_path, datasets
        if "window_state" in session.layout:
            self.restoreState(QByteArray.fromBase64(session.layout["window_state"].encode("ascii")))
        self.plotter.render()
        self.setWindowTitle(f"volviz — {title}")
        self.status_label.setText(f"Showing {title}")

    # ------------------------------------------------------------------------------------------------ saving
    def capture_session(self, target: Path) -> Session:
        """The current state as a session to be saved at ``target`` (paths made relative to it)."""
        from volviz.render.vtk_scene import camera_state
        from volviz.session import DatasetRef, resolve_path

        session = self.session
        refs = []
        for ref in session.datasets:
            absolute = resolve_path(self.session_path, ref.path) if self.session_path else Path(ref.path)
            refs.append(DatasetRef(ref.id, relative_path(target, absolute), dict(ref.options)))
        layout = dict(session.layout)
        layout["window_state"] = bytes(self.saveState().toBase64()).decode("ascii")
        return Session(datasets=refs, components=session.components, transfer_functions=session.transfer_functions,
                       camera=camera_state(self.plotter), camera_paths=session.camera_paths,
                       bookmarks=session.bookmarks, render=session.render, layout=layout)

    def save_session(self, path: str | os.PathLike) -> bool:
        from volviz.session import save

        target = Path(path)
        try:
            session = self.capture_session(target)
            save(session, target)
        except SessionError as exc:
            self.show_error("Cannot save session", str(exc))
            return False
        self.session, self.session_path = session, target
        self.status_label.setText(f"Saved {target.name}")
        return True

    def export_screenshot(self, path: str | os.PathLike, size: Optional[tuple[int, int]] = None) -> bool:
        """Re-render the current view offscreen at ``size`` (default: the viewport's) and write a PNG."""
        from volviz.render.export import offscreen_plotter, write_png
        from volviz.render.scene import build_scene
        from volviz.render.vtk_scene import camera_state

        width, height = size or (self.plotter.interactor.width(), self.plotter.interactor.height())
        plotter = offscreen_plotter((width, height))
        try:
            session = Session(datasets=self.session.datasets, components=self.session.components,
                              transfer_functions=self.session.transfer_functions, camera=camera_state(self.plotter),
                              render=self.session.render)
            build_scene(plotter, session, self.datasets)
            image = plotter.screenshot(None, return_img=True, window_size=[width, height])
            write_png(image, path)
        except Exception as exc:
            log.exception("screenshot export failed")
            self.show_error("Cannot export screenshot", f"{path}: {exc}")
            return False
        finally:
            plotter.close()
        self.status_label.setText(f"Exported {Path(path).name} ({width}x{height})")
        return True

    # ------------------------------------------------------------------------------------------------ dialogs
    def _ask_open_data(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Open data", "", _data_filter())
        if path:
            self.open_path(path)

    def _ask_open_session(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Open session", "", "volviz sessions (*.json);;All files (*)")
        if path:
            self.open_path(path)

    def _save_session(self) -> None:
        if self.session_path is None:
            self._ask_save_session_as()
        else:
            self.save_session(self.session_path)

    def _ask_save_session_as(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Save session", "session.json", "volviz sessions (*.json)")
        if path:
            self.save_session(path)

    def _ask_export_screenshot(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Export screenshot", "volviz.png", "PNG images (*.png)")
        if path:
            self.export_screenshot(path)

    def show_error(self, title: str, text: str) -> None:
        """A non-blocking error dialog (the app keeps running); also logged."""
        log.error("%s: %s", title, text)
        dialog = QMessageBox(QMessageBox.Icon.Critical, title, text, QMessageBox.StandardButton.Ok, self)
        dialog.setWindowModality(Qt.WindowModality.WindowModal)
        dialog.open()
        self.error_dialog = dialog

    # ------------------------------------------------------------------------------------------------ progress
    def _on_progress(self, job_id: int, fraction: float, message: str) -> None:
        self.progress_bar.setValue(int(round(fraction * 1000)))
        if message:
            self.status_label.setText(message)

    def _set_busy(self, busy: bool) -> None:
        self.progress_bar.setVisible(busy)
        self.cancel_button.setVisible(busy)
        if busy:
            self.progress_bar.setValue(0)

    def cancel_current_job(self) -> None:
        if self._current_job is not None:
            self._current_job.cancel()

    def closeEvent(self, event: Any) -> None:
        self.jobs.shutdown()
        self.plotter.close()
        super().closeEvent(event)
