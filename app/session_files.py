"""Session I/O of the main window: File > Open Data / Open Folder / Open Session / Save Session / Save Session As
(non-blocking file dialogs that start in the folder used last), saving, dirty tracking in the window title, autosave
to a crash-recovery file of the window's own (``volviz_app.recovery``) with the offer to restore one left by a
crash, File > Open Recent (``volviz_app.recent``), and the question about unsaved changes on closing.

Held by the window as ``window.session_files``; its collaborators are the shown scene (``shown_scene``: it saves the
session, marks it dirty, and takes a saved session as the shown one), the window (the parent of its dialogs and
timers, its title and dock state), the recovery folder, the recent files, the status label, and the window's scene
loading: ``open_path(path)``, ``open_paths(paths)`` and ``show_session(session, session_path, title, dirty=...)``
(``volviz_app.scene_loading``), with ``show_error(title, text)``. Its autosave timer runs from when it is made;
``stop()`` ends it when the window closes."""
from __future__ import annotations

import dataclasses
import logging
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Optional

from PySide6.QtCore import QStandardPaths, QTimer
from PySide6.QtWidgets import QFileDialog, QLabel, QMainWindow, QMessageBox

from volviz.session import Session, SessionError, relative_path
from .recent import RecentFiles
from .shown_scene import ShownScene

if TYPE_CHECKING:
    OpenPath = Callable[[str | os.PathLike], None]

log = logging.getLogger("volviz_app.window")  # the logger these methods had in window.py

AUTOSAVE_MS = 60_000     # the recovery file is rewritten at least this often while there are unsaved changes
EDIT_AUTOSAVE_MS = 1_500  # and this long after every edit, so a crash loses at most the last moments


PLOT3D_SOLUTIONS = "*.q *q.bin *q*.bin *q.dat *.sol"   # the solution files picked beside a PLOT3D grid


def _data_filter() -> str:
    """The readers' filter plus volviz's own compressed volumes and the PLOT3D solution files the dialog asks for
    beside a grid (the grid's patterns, ``*xyz*.bin``, hid ``bluntfinq.bin``)."""
    from volviz.io import open_dialog_filter

    everything, rest = open_dialog_filter().split(";;", 1)
    rest = rest.replace("PLOT3D grid (+ q solution) (", f"PLOT3D grid (+ q solution) ({PLOT3D_SOLUTIONS} ", 1)
    return (everything.replace("(", f"(*.vvz {PLOT3D_SOLUTIONS} ", 1) + ";;volviz compressed volume (*.vvz);;"
            + rest)


def default_recovery_dir() -> Path:
    env = os.environ.get("VOLVIZ_RECOVERY_DIR")
    if env:
        return Path(env)
    base = QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)
    return Path(base or Path.home() / ".volviz") / "recovery"


class SessionFiles:
    """Open, save, autosave, recovery, recent files and dirty tracking of the window (see the module's docstring)."""

    def __init__(self, scene: ShownScene, window: QMainWindow, recovery_dir: Path, recent: RecentFiles,
                 status: QLabel, open_path: OpenPath, open_paths: Callable[[list[str]], None],
                 show_session: Callable[..., None], show_error: Callable[[str, str], None]) -> None:
        self.scene, self.window, self.recovery_dir = scene, window, recovery_dir
        self.recent, self.status, self.show_error = recent, status, show_error
        self.open_path, self.open_paths, self.show_session = open_path, open_paths, show_session
        self.file_dialog: Optional[QFileDialog] = None       # the last file dialog (``ask_file``)
        self.unsaved_dialog: Optional[QMessageBox] = None    # the last unsaved-changes question
        self.recovery_dialog: Optional[QMessageBox] = None   # the offer to restore a crashed window's work
        self._recovery_file: Optional[Path] = None
        self.autosave_timer = QTimer(window, interval=AUTOSAVE_MS)
        self.autosave_timer.timeout.connect(self.autosave)
        self.autosave_timer.start()
        self.edit_autosave_timer = QTimer(window, singleShot=True, interval=EDIT_AUTOSAVE_MS)
        self.edit_autosave_timer.timeout.connect(self.autosave)

    def stop(self) -> None:
        """The window closes: no more autosaves."""
        self.autosave_timer.stop()
        self.edit_autosave_timer.stop()

    def set_dirty(self, dirty: bool = True) -> None:
        self.scene.dirty = dirty
        if dirty:
            self.edit_autosave_timer.start()  # (re)started by each edit: one write after a burst of edits
        path = self.scene.session_path
        name = path.name if path else getattr(self.scene, "title", "untitled")
        self.window.setWindowTitle(f"volviz — {name}{' *' if dirty else ''}")

    def capture_session(self, target: Path) -> Session:
        """The current state as a session to be saved at ``target`` (paths made relative to it)."""
        from volviz.session import DatasetRef, resolve_path

        session, session_path, controller = self.scene.session, self.scene.session_path, self.scene.controller
        refs = []
        for ref in session.datasets:
            absolute = resolve_path(session_path, ref.path) if session_path else Path(ref.path)
            refs.append(DatasetRef(ref.id, relative_path(target, absolute), dict(ref.options)))
        layout = dict(session.layout)
        layout["window_state"] = self.window.saveState().toBase64().toStdString()
        camera = controller.camera() if controller is not None else session.camera
        render = session.render
        if controller is not None and controller.time_series():  # the time shown is what reopens
            render = dataclasses.replace(render, options={**render.options, "time": float(controller.time)})
        return Session(datasets=refs, components=session.components, transfer_functions=session.transfer_functions,
                       camera=camera, camera_paths=session.camera_paths, bookmarks=session.bookmarks,
                       render=render, layout=layout, clip=session.clip)

    def save_session(self, path: str | os.PathLike) -> bool:
        from volviz.session import save

        target = Path(path)
        try:
            session = self.capture_session(target)
            save(session, target)
        except SessionError as exc:
            self.show_error("Cannot save session", str(exc))
            return False
        shown = self.scene.session   # kept, not swapped for the one saved: a script's ``session`` (the Python
        shown.datasets[:] = session.datasets   # console's) and the scene's subscription stay on it (issue #28)
        shown.camera, shown.render, shown.layout = session.camera, session.render, session.layout
        self.scene.session_path = target
        if self.scene.controller is not None and self.scene.controller.session is not shown:
            self.scene.controller.session = shown
        self.recent.add(target)
        self.set_dirty(False)
        self.clear_recovery()
        self.status.setText(f"Saved {target.name}")
        return True

    @property
    def recovery_file(self) -> Path:
        """This window's own recovery file (``volviz_app.recovery``): other windows never write or delete it."""
        from .recovery import window_file

        if self._recovery_file is None:
            self._recovery_file = window_file(self.recovery_dir)
        return self._recovery_file

    def autosave(self) -> bool:
        """Write the current state to the recovery file (only when there are unsaved changes)."""
        if not self.scene.dirty or self.scene.controller is None:
            return False
        from volviz.session import save

        self.recovery_dir.mkdir(parents=True, exist_ok=True)
        session = self.capture_session(self.recovery_file)
        session.layout["recovered_from"] = str(self.scene.session_path) if self.scene.session_path else ""
        try:
            save(session, self.recovery_file)
        except SessionError as exc:
            log.error("autosave failed: %s", exc)
            return False
        self.status.setText("Autosaved")
        return True

    def clear_recovery(self) -> None:
        self.recovery_file.unlink(missing_ok=True)

    def offer_recovery(self) -> bool:
        """If a crashed window (its process is gone) left a recovery file, claim it as this window's own and ask
        (without blocking) whether to restore it."""
        from .recovery import claim, orphaned

        if not any(claim(orphan, self.recovery_file) for orphan in orphaned(self.recovery_dir)):
            return False
        box = QMessageBox(QMessageBox.Icon.Question, "Recover unsaved work",
                          "volviz did not shut down cleanly last time. Restore the unsaved work it kept?",
                          QMessageBox.StandardButton.Yes | QMessageBox.StandardButton.No, self.window)
        box.finished.connect(lambda result: self._recovery_answer(box.result()))
        box.open()
        self.recovery_dialog = box
        return True

    def _recovery_answer(self, result: int) -> None:
        if result == QMessageBox.StandardButton.Yes:
            self.recover()
        else:
            self.clear_recovery()

    def recover(self) -> None:
        from volviz.session import load

        try:
            session = load(self.recovery_file)
        except SessionError as exc:
            self.show_error("Cannot recover", str(exc))
            return
        origin = session.layout.pop("recovered_from", "")
        if origin:  # keep paths valid relative to the original session file when saved there again
            from volviz.session import resolve_path

            for ref in session.datasets:
                ref.path = relative_path(origin, resolve_path(self.recovery_file, ref.path))
        self.show_session(session, Path(origin) if origin else None, "recovered session", dirty=True)

    def recent_files(self) -> list[str]:
        """File > Open Recent: the files that opened, newest first (``volviz_app.recent``)."""
        return self.recent.files()

    def ask_file(self, title: str, name_filter: str, on_chosen: Any, save: bool = False,
                 default_name: str = "", multiple: bool = False, folder: bool = False) -> QFileDialog:
        """A non-blocking file dialog (kept as ``self.file_dialog``) that starts in the folder used last;
        ``on_chosen(path)`` runs when accepted. ``folder``: it chooses a folder, and the next dialog starts in the
        folder that holds it (among its siblings)."""
        dialog = QFileDialog(self.window, title, self.recent.last_folder(), name_filter)
        dialog.setOption(QFileDialog.Option.DontUseNativeDialog, True)
        if save:
            dialog.setAcceptMode(QFileDialog.AcceptMode.AcceptSave)
            dialog.setFileMode(QFileDialog.FileMode.AnyFile)
            if default_name:
                dialog.selectFile(default_name)
        elif multiple:   # ``on_chosen(paths)`` gets the list
            dialog.setFileMode(QFileDialog.FileMode.ExistingFiles)

            def files_selected(paths: list[str]) -> None:
                if paths:
                    self.recent.remember_folder(paths[0])
                    on_chosen(list(paths))

            dialog.filesSelected.connect(files_selected)
        elif folder:
            dialog.setFileMode(QFileDialog.FileMode.Directory)
            dialog.setOption(QFileDialog.Option.ShowDirsOnly, True)
        else:
            dialog.setFileMode(QFileDialog.FileMode.ExistingFile)

        def file_selected(path: str) -> None:
            if path and not multiple:
                self.recent.remember_folder(Path(path).parent if folder else path)
                on_chosen(path)

        dialog.fileSelected.connect(file_selected)
        _fit_to_window(dialog, self.window)
        dialog.open()
        self.file_dialog = dialog
        return dialog

    def ask_open_data(self) -> None:
        self.keeping_unsaved_work(lambda: self.ask_file("Open data (a PLOT3D grid with its solution: select both)",
                                                        _data_filter(), self.open_paths, multiple=True))

    def ask_open_folder(self) -> None:
        self.keeping_unsaved_work(lambda: self.ask_file("Open a folder (a DICOM series, an OpenFOAM case)", "",
                                                        self.open_path, folder=True))

    def ask_open_session(self) -> None:
        self.keeping_unsaved_work(lambda: self.ask_file("Open session", "volviz sessions (*.json);;All files (*)",
                                                        self.open_path))

    def open_path_asking(self, path: str | os.PathLike) -> None:
        """``open_path`` for what replaces the scene at the user's word (File > Open Recent, a drop): unsaved
        changes are asked about first (``keeping_unsaved_work``)."""
        self.keeping_unsaved_work(lambda: self.open_path(path))

    def keeping_unsaved_work(self, then: Any) -> None:
        """Run ``then()`` (which replaces the scene) now if nothing is unsaved; else ask, without blocking, Save /
        Discard / Cancel (kept as ``unsaved_dialog``): Save saves (asking for a file when the session has none) and
        then goes on, Discard goes on, Cancel keeps everything as it is."""
        if not self.scene.dirty:
            then()
            return
        box = QMessageBox(QMessageBox.Icon.Warning, "Unsaved changes",
                          "The scene has unsaved changes. Save them before opening another?",
                          QMessageBox.StandardButton.Save | QMessageBox.StandardButton.Discard
                          | QMessageBox.StandardButton.Cancel, self.window)

        def answered(_: int) -> None:
            answer = box.standardButton(box.clickedButton()) if box.clickedButton() else None
            if answer == QMessageBox.StandardButton.Discard:
                then()
            elif answer == QMessageBox.StandardButton.Save:
                session_path = self.scene.session_path
                if session_path is not None:
                    if self.save_session(session_path):
                        then()
                else:
                    self.ask_file("Save session", "volviz sessions (*.json)",
                                  lambda p: self.save_session(p) and then(), save=True, default_name="session.json")

        box.finished.connect(answered)
        box.open()
        self.unsaved_dialog = box

    def save(self) -> bool:
        """File > Save Session: to the session's file, else asking for one (False: not saved now)."""
        session_path = self.scene.session_path
        if session_path is None:
            self.ask_save_as()
            return False
        return self.save_session(session_path)

    def ask_save_as(self) -> None:
        self.ask_file("Save session", "volviz sessions (*.json)", self.save_session, save=True,
                      default_name="session.json")

    def ask_unsaved_changes(self) -> QMessageBox.StandardButton:
        box = QMessageBox(QMessageBox.Icon.Warning, "Unsaved changes", "Save the changes to this session?",
                          QMessageBox.StandardButton.Save | QMessageBox.StandardButton.Discard
                          | QMessageBox.StandardButton.Cancel, self.window)
        self.unsaved_dialog = box
        return QMessageBox.StandardButton(box.exec())

    def confirm_close(self) -> bool:
        """Closing with unsaved changes asks whether to save them; False: the window stays open (Cancel, or Save
        and the session was not saved)."""
        if not self.scene.dirty:
            return True
        answer = self.ask_unsaved_changes()
        return not (answer == QMessageBox.StandardButton.Cancel or (
            answer == QMessageBox.StandardButton.Save and not self.save()))


DIALOG_SHARE = 0.8   # of the window's width and height a file dialog takes


def _fit_to_window(dialog: QFileDialog, window: Any) -> None:
    """Most of the window (``DIALOG_SHARE``), within its screen, centred on it: Qt's own 632x412 cut the Size and
    Date Modified columns of the file list (issue #28, a new user's 1366x768 screen)."""
    screen = window.screen().availableGeometry()
    width = min(int(window.width() * DIALOG_SHARE), screen.width())
    height = min(int(window.height() * DIALOG_SHARE), screen.height())
    dialog.resize(width, height)
    frame = dialog.frameGeometry()
    frame.moveCenter(window.frameGeometry().center())
    dialog.move(min(max(frame.x(), screen.left()), screen.right() - frame.width() + 1),
                min(max(frame.y(), screen.top()), screen.bottom() - frame.height() + 1))
