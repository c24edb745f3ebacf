"""The Isosurfaces dock: the surfaces of the scene's isosurface component (value, colour, opacity), editors to add
one, change the selected one or remove it, and the transparency mode of the isosurfaces (VTK's blend, the 2-, 3-
or 4-pass modes of the libMini note §4, or its exact per-pixel sorted reference). The window's iso tool
(``volviz_app.iso_tool``) turns the signals into undoable scene edits."""
from __future__ import annotations

from typing import Any, Optional

from PySide6.QtCore import Qt, Signal
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (QAbstractItemView, QColorDialog, QComboBox, QDoubleSpinBox, QFormLayout, QHBoxLayout,
                               QLabel, QPushButton, QSizePolicy, QTableWidget, QTableWidgetItem, QVBoxLayout, QWidget)

from volviz.session import ISO_MODES

_LABELS = {"vtk": "VTK blend", "2pass": "2-pass", "3pass": "3-pass", "4pass": "4-pass", "exact": "Exact (sorted)"}
#: the transparency modes offered (every render option ``iso_mode`` the session accepts), with their labels
MODES = {mode: _LABELS[mode] for mode in ISO_MODES}


class IsosurfacesDock(QWidget):
    """The list of surfaces and their editors (module docstring). Signals: ``added(style)``, ``edited(row, style)``,
    ``removed(row)``, ``modeChosen(mode)``; a style is ``{"value", "color", "opacity"}``."""

    added = Signal(dict)
    edited = Signal(int, dict)
    removed = Signal(int)
    modeChosen = Signal(str)

    def __init__(self, parent: Optional[QWidget] = None) -> None:
        super().__init__(parent)
        self.table = QTableWidget(0, 3)
        self.table.setHorizontalHeaderLabels(["Value", "Color", "Opacity"])
        self.table.setSelectionBehavior(QAbstractItemView.SelectionBehavior.SelectRows)
        self.table.setSelectionMode(QAbstractItemView.SelectionMode.SingleSelection)
        self.table.setEditTriggers(QAbstractItemView.EditTrigger.NoEditTriggers)
        self.table.verticalHeader().setVisible(False)
        self.table.setMinimumHeight(90)
        # its height is what the editors leave (at least 90): once the word-wrapped note had text ("Isosurfaces need a
        # volume." after the demo) the dock's scroll area sized the dock by height-for-width from the table's 192-pixel
        # hint and hid Add/Apply/Remove below the fold of a 1366x768 screen (issue #28)
        policy = self.table.sizePolicy()
        policy.setVerticalPolicy(QSizePolicy.Policy.Ignored)
        self.table.setSizePolicy(policy)
        self.value = QDoubleSpinBox()
        self.value.setDecimals(4)
        self.value.setRange(-1e12, 1e12)
        self.opacity = QDoubleSpinBox()
        self.opacity.setDecimals(2)
        self.opacity.setRange(0.0, 1.0)
        self.opacity.setSingleStep(0.05)
        self.opacity.setValue(0.5)
        self.color_button = QPushButton()
        self.color_button.clicked.connect(self._ask_color)
        self.color: Optional[tuple[float, float, float]] = None    # None: the transfer function's colour at the value
        self.add_button = QPushButton("Add")
        self.apply_button = QPushButton("Apply")
        self.remove_button = QPushButton("Remove")
        self.mode = QComboBox()
        for key, label in MODES.items():
            self.mode.addItem(label, key)
        for widget, tip in ((self.table, "The isosurfaces: select one to edit or remove it"),
                            (self.value, "Iso-value of a new or the selected surface"),
                            (self.opacity, "Opacity of a new or the selected surface"),
                            (self.color_button, "Color of a new or the selected surface"),
                            (self.add_button, "Add a surface at the value"),
                            (self.apply_button, "Give the selected surface the value, color and opacity above"),
                            (self.remove_button, "Remove the selected surface"),
                            (self.mode, "How translucent surfaces are blended: VTK, 2-, 3- or 4-pass, or exact "
                                        "(sorted per pixel)")):
            widget.setToolTip(tip)
        self.note = QLabel("")
        self.note.setWordWrap(True)
        form = QFormLayout()
        form.addRow("Value", self.value)
        form.addRow("Color", self.color_button)
        form.addRow("Opacity", self.opacity)
        buttons = QHBoxLayout()
        for b in (self.add_button, self.apply_button, self.remove_button):
            buttons.addWidget(b)
        layout = QVBoxLayout(self)
        layout.addWidget(self.table, 1)
        layout.addLayout(form)
        layout.addLayout(buttons)
        mode_row = QFormLayout()
        mode_row.addRow("Transparency", self.mode)
        layout.addLayout(mode_row)
        layout.addWidget(self.note)
        self.add_button.clicked.connect(lambda: self.added.emit(self.current_style()))
        self.apply_button.clicked.connect(self._apply)
        self.remove_button.clicked.connect(self._remove)
        self.table.itemSelectionChanged.connect(self._selected)
        self.mode.activated.connect(lambda _i: self.modeChosen.emit(str(self.mode.currentData())))
        self._show_color()
        self.set_enabled(False)

    def current_style(self) -> dict[str, Any]:
        """The editors' surface (``color`` None: the tool picks the transfer function's colour)."""
        return {"value": float(self.value.value()), "color": self.color, "opacity": float(self.opacity.value())}

    def selected_row(self) -> Optional[int]:
        rows = self.table.selectionModel().selectedRows()
        return rows[0].row() if rows else None

    def _apply(self) -> None:
        row = self.selected_row()
        if row is not None:
            self.edited.emit(row, self.current_style())

    def _remove(self) -> None:
        row = self.selected_row()
        if row is not None:
            self.removed.emit(row)

    def _ask_color(self) -> None:
        start = QColor.fromRgbF(*(self.color or (1.0, 1.0, 1.0)))
        dialog = QColorDialog(start, self)
        dialog.setWindowTitle("Isosurface color")
        dialog.colorSelected.connect(lambda c: self.set_color((c.redF(), c.greenF(), c.blueF())))
        dialog.open()
        self.color_dialog = dialog

    def set_color(self, color: Optional[tuple[float, float, float]]) -> None:
        self.color = None if color is None else tuple(float(c) for c in color)  # type: ignore[assignment]
        self._show_color()

    def _show_color(self) -> None:
        if self.color is None:
            self.color_button.setText("from the transfer function")
            self.color_button.setStyleSheet("")
            return
        self.color_button.setText("")
        self.color_button.setStyleSheet(f"background-color: {QColor.fromRgbF(*self.color).name()}")

    def _selected(self) -> None:
        row = self.selected_row()
        if row is None:
            return
        style = self.styles[row]
        self.value.setValue(style["value"])
        self.opacity.setValue(style["opacity"])
        self.set_color(tuple(style["color"]))

    def set_enabled(self, on: bool, note: str = "") -> None:
        for w in (self.table, self.value, self.opacity, self.color_button, self.add_button, self.apply_button,
                  self.remove_button, self.mode):
            w.setEnabled(on)
        self.note.setText(note)

    def load(self, styles: list[dict[str, Any]], mode: str, value_range: Optional[tuple[float, float]]) -> None:
        """Show the component's surfaces, the scene's transparency mode, and start new values inside ``value_range``
        (the data's) when the editors hold none yet."""
        self.styles = [dict(s) for s in styles]
        self.table.setRowCount(len(styles))
        for row, s in enumerate(self.styles):
            color = QColor.fromRgbF(*s["color"])
            items = [QTableWidgetItem(f"{s['value']:g}"), QTableWidgetItem(color.name()),
                     QTableWidgetItem(f"{s['opacity']:.2f}")]
            items[1].setBackground(color)
            for col, item in enumerate(items):
                item.setTextAlignment(Qt.AlignmentFlag.AlignCenter)
                self.table.setItem(row, col, item)
        self.mode.setCurrentIndex(max(0, self.mode.findData(mode)))
        if value_range is not None and not styles and self.value.value() == 0.0:
            self.value.setValue(0.5 * (value_range[0] + value_range[1]))

    styles: list[dict[str, Any]] = []
