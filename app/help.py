"""Help > Keyboard Shortcuts and Help > About.

The shortcut list is made from the window's menus when the dialog opens (every action with a shortcut, under the menu
that holds it) and from fly mode's key table, so it cannot fall out of step with what the keys do."""
from __future__ import annotations

from typing import Any, Callable, Optional

from PySide6.QtGui import QAction, QKeySequence
from PySide6.QtWidgets import (QDialog, QDialogButtonBox, QLabel, QMainWindow, QMenu, QMessageBox, QTableWidget,
                               QTableWidgetItem, QVBoxLayout, QWidget)


def _plain(text: str) -> str:
    return text.replace("&", "").replace("…", "").strip()


def menu_shortcuts(window: QMainWindow) -> list[tuple[str, str, str]]:
    """(key sequence, menu path, what it does) for every action with a shortcut in the window's menus."""
    rows: list[tuple[str, str, str]] = []

    def walk(menu: QMenu, path: str) -> None:
        for action in menu.actions():
            sub = action.menu()
            if isinstance(sub, QMenu):
                walk(sub, f"{path} > {_plain(action.text())}")
            elif not action.isSeparator() and not action.shortcut().isEmpty():
                keys = action.shortcut().toString(QKeySequence.SequenceFormat.NativeText)
                rows.append((keys, path, _plain(action.text()) or action.toolTip()))

    for top in window.menuBar().actions():
        menu = top.menu()
        if isinstance(menu, QMenu):
            walk(menu, _plain(top.text()))
    return rows


def fly_shortcuts() -> list[tuple[str, str, str]]:
    """Fly mode's keys (``volviz_app.navigation.MOVES``), one row per motion."""
    from PySide6.QtCore import Qt

    from .navigation import MOVES

    names = {(1, 0, 0): "move forward", (-1, 0, 0): "move back", (0, 1, 0): "move right", (0, -1, 0): "move left",
             (0, 0, 1): "rise", (0, 0, -1): "sink"}
    keys: dict[tuple[int, int, int], list[str]] = {}
    for key, move in MOVES.items():
        keys.setdefault(move, []).append(QKeySequence(Qt.Key(key)).toString(QKeySequence.SequenceFormat.NativeText))
    return [(" / ".join(k), "Fly mode", names.get(move, str(move))) for move, k in keys.items()]


class ShortcutsDialog(QDialog):
    """A table of every shortcut of ``window`` (``menu_shortcuts``, then fly mode's keys)."""

    def __init__(self, window: QMainWindow) -> None:
        super().__init__(window)
        self.setWindowTitle("Keyboard shortcuts")
        self.rows = menu_shortcuts(window) + fly_shortcuts()
        self.table = QTableWidget(len(self.rows), 3)
        self.table.setHorizontalHeaderLabels(["Keys", "Where", "Does"])
        self.table.verticalHeader().setVisible(False)
        self.table.setEditTriggers(QTableWidget.EditTrigger.NoEditTriggers)
        for r, row in enumerate(self.rows):
            for c, text in enumerate(row):
                self.table.setItem(r, c, QTableWidgetItem(text))
        self.table.resizeColumnsToContents()
        self.table.horizontalHeader().setStretchLastSection(True)
        buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Close)
        buttons.rejected.connect(self.reject)
        layout = QVBoxLayout(self)
        layout.addWidget(QLabel("In the viewport: drag to rotate, right-drag or wheel to zoom, middle-drag (or "
                                "Shift+drag) to pan."))
        layout.addWidget(self.table)
        layout.addWidget(buttons)
        self.resize(560, 520)


def opengl_renderer(render_window: Any) -> str:
    """The OpenGL renderer string of a VTK render window (which GPU, or Mesa's software renderer), or "unknown"."""
    try:
        report = render_window.ReportCapabilities() or ""
    except Exception:  # no context (closed window): not worth failing the About box for
        return "unknown"
    for line in report.splitlines():
        if line.lower().startswith("opengl renderer string:"):
            return line.split(":", 1)[1].strip()
    return "unknown"


def about_text(render_window: Optional[Any] = None) -> str:
    """volviz's version and the versions it runs on (VTK, Qt, PySide6, PyVista), and the OpenGL renderer."""
    from importlib.metadata import PackageNotFoundError, version

    import pyvista
    import PySide6
    from PySide6.QtCore import qVersion
    from vtkmodules.vtkCommonCore import vtkVersion

    try:
        volviz_version = version("volviz")
    except PackageNotFoundError:
        volviz_version = "development copy"
    lines = [f"volviz {volviz_version}", "",
             "Volume rendering of meshes, regular volumes and natural scenes.", "",
             f"VTK {vtkVersion.GetVTKVersion()}", f"Qt {qVersion()} (PySide6 {PySide6.__version__})",
             f"PyVista {pyvista.__version__}"]
    if render_window is not None:
        lines.append(f"OpenGL renderer: {opengl_renderer(render_window)}")
    return "\n".join(lines)


class HelpMenu:
    """The Help menu of ``window``: Keyboard Shortcuts and About (the open dialog is kept as ``dialog``).
    ``render_window`` gives the viewport's render window when asked (None once closed): holding the render window
    would keep a closed native viewport's X connection open (``app/native_viewport.py``)."""

    def __init__(self, window: QMainWindow, menu: QMenu, render_window: Callable[[], Any]) -> None:
        self.window, self.render_window = window, render_window
        self.dialog: Optional[QWidget] = None
        self.action_shortcuts = QAction("&Keyboard Shortcuts", window)
        self.action_shortcuts.setShortcut(QKeySequence(QKeySequence.StandardKey.HelpContents))
        self.action_shortcuts.triggered.connect(self.show_shortcuts)
        self.action_about = QAction("&About volviz", window)
        self.action_about.triggered.connect(self.show_about)
        menu.addAction(self.action_shortcuts)
        menu.addAction(self.action_about)

    def show_shortcuts(self) -> ShortcutsDialog:
        dialog = ShortcutsDialog(self.window)
        dialog.open()
        self.dialog = dialog
        return dialog

    def show_about(self) -> QMessageBox:
        box = QMessageBox(QMessageBox.Icon.Information, "About volviz", about_text(self.render_window()),
                          QMessageBox.StandardButton.Ok, self.window)
        box.open()
        self.dialog = box
        return box
