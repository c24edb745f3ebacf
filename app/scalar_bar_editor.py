"""View > Edit Scalar Bar… (or a double click on the scalar bar): its title, a fixed range or the transfer
function's, and the number format of its labels. Saved in the session as the render option ``scalar_bar_style``
(``volviz.model.settings.ScalarBarStyle``), so ``volviz render`` draws the same bar. Each accepted edit is one step
on the window's scene undo stack (Edit > Undo puts the previous bar back)."""
from __future__ import annotations

from typing import Any, Optional

from PySide6.QtCore import QEvent, QObject
from PySide6.QtGui import QAction
from PySide6.QtWidgets import (QCheckBox, QDialog, QDialogButtonBox, QFormLayout, QLabel, QLineEdit, QMenu,
                               QVBoxLayout, QWidget)

from volviz.model.settings import SettingsError, validate_render_options

from .shown_edit import ShownEdit


class ScalarBarDialog(QDialog):
    """The form: ``title`` (empty: the array's name), ``fixed`` with ``low`` / ``high`` (unchecked: follow the
    transfer function), ``fmt`` (empty: chosen from the range); ``error`` says what is wrong with the input."""

    def __init__(self, style: dict[str, Any], parent: Optional[QWidget] = None) -> None:
        super().__init__(parent)
        self.setWindowTitle("Scalar Bar")
        self.title = QLineEdit(str(style.get("title") or ""))
        self.title.setPlaceholderText("the shown array's name")
        rng = style.get("range")
        self.fixed = QCheckBox("Fixed range (else the transfer function's)")
        self.fixed.setChecked(rng is not None)
        self.low = QLineEdit("" if rng is None else repr(float(rng[0])))
        self.high = QLineEdit("" if rng is None else repr(float(rng[1])))
        self.fmt = QLineEdit(str(style.get("format") or ""))
        self.fmt.setPlaceholderText("automatic, e.g. %.3g")
        self.error = QLabel("")
        self.error.setStyleSheet("color: #c03030")
        form = QFormLayout()
        form.addRow("Title", self.title)
        form.addRow(self.fixed)
        form.addRow("Low", self.low)
        form.addRow("High", self.high)
        form.addRow("Number format", self.fmt)
        self.buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Ok | QDialogButtonBox.StandardButton.Cancel)
        self.buttons.rejected.connect(self.reject)
        column = QVBoxLayout(self)
        column.addLayout(form)
        column.addWidget(self.error)
        column.addWidget(self.buttons)

    def edited_style(self) -> dict[str, Any]:
        """The edited style (only the fields set); ValueError naming the field when a number does not read."""
        out: dict[str, Any] = {}
        if self.title.text().strip():
            out["title"] = self.title.text().strip()
        if self.fixed.isChecked():
            try:
                out["range"] = [float(self.low.text()), float(self.high.text())]
            except ValueError:
                raise ValueError("Low and High must be numbers") from None
        if self.fmt.text().strip():
            out["format"] = self.fmt.text().strip()
        return out


class ScalarBarEditor(QObject):
    """The menu action and the double click on the bar; ``window`` provides ``session``, ``controller``,
    ``plotter``, ``scene_undo_stack``, ``set_dirty`` and ``render_scene``. ``dialog`` is the open dialog (None when
    closed)."""

    def __init__(self, window: Any, menu: QMenu) -> None:
        super().__init__(window)
        self.window = window
        self.dialog: Optional[ScalarBarDialog] = None
        self.action = QAction("Edit Scalar &Bar…", window)
        self.action.setStatusTip("The scalar bar's title, range and number format")
        self.action.triggered.connect(self.ask)
        menu.addAction(self.action)
        window.plotter.interactor.installEventFilter(self)

    def eventFilter(self, watched: Any, event: Any) -> bool:  # noqa: N802 (Qt's name)
        if event.type() == QEvent.Type.MouseButtonDblClick:
            from volviz.render.decorations import scalar_bar_hit

            pos = event.position()
            ratio = watched.devicePixelRatioF()
            height = self.window.plotter.ren_win.GetSize()[1]
            if scalar_bar_hit(self.window.plotter, pos.x() * ratio, height - 1 - pos.y() * ratio):
                self.ask()
                return True
        return False

    def ask(self) -> None:
        """Open the dialog on the session's style (non-blocking); OK applies it."""
        self.dialog = ScalarBarDialog(self.style(), self.window)
        self.dialog.buttons.accepted.connect(self._accept)
        self.dialog.finished.connect(self._closed)
        self.dialog.open()

    def _closed(self) -> None:
        self.dialog = None

    def _accept(self) -> None:
        dialog = self.dialog
        if dialog is None:
            return
        try:
            style = dialog.edited_style()
            validate_render_options({"scalar_bar_style": style})
        except (ValueError, SettingsError) as exc:
            dialog.error.setText(str(exc).replace("render.options.scalar_bar_style.", ""))
            return
        self.apply(style)
        dialog.accept()

    def style(self) -> dict[str, Any]:
        """The session's scalar bar style (``{}``: all follow the data)."""
        return dict(self.window.session.render.options.get("scalar_bar_style") or {})

    def apply(self, style: dict[str, Any]) -> None:
        """Show ``style`` (``{}``: all follow the data) as one step on the scene undo stack; nothing when unchanged."""
        before = self.style()
        if before == style:
            return
        self.show_style(style)
        self.window.scene_undo_stack.push(ShownEdit("Edit the scalar bar", before, style, self.show_style))

    def show_style(self, style: dict[str, Any]) -> None:
        """Set the session's scalar bar style and redraw the bar (an edit, or an undo or redo step)."""
        window = self.window
        if style:
            window.session.render.options["scalar_bar_style"] = dict(style)
        else:
            window.session.render.options.pop("scalar_bar_style", None)
        window.set_dirty()
        if window.controller is not None:
            window.controller.decorate()
            window.render_scene()
