"""Transfer-function editor dock: extinction curve with draggable control points over the data histogram, color
stops with a color picker, presets (ParaView JSON import/export), fit to data range, undo/redo.

The editor holds a ``TransferFunction`` (volviz.optics) and never computes optics itself; where a point goes when
one is added, moved or removed is ``volviz.optics.tf_points``. It emits ``changed(tf)`` continuously while the user
drags (the window throttles re-rendering) and ``committed(tf)`` when an edit is finished; each finished edit is one
entry of the undo stack. With the component's log color scale on (``set_log_axis``), the scalar axis is in log10
from the scale's smallest positive value, with its ticks labelled, so the color bar reads as the volume is colored
(``volviz.optics.log_scale``).
"""
from __future__ import annotations

from typing import Any, Optional

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QBrush, QColor, QLinearGradient, QPainter, QPainterPath, QPen, QUndoCommand, QUndoStack
from PySide6.QtWidgets import (QCheckBox, QColorDialog, QComboBox, QFileDialog, QHBoxLayout, QLabel, QMessageBox,
                               QPushButton, QSizePolicy, QVBoxLayout, QWidget)

from volviz.optics import TransferFunction
from volviz.optics.log_scale import axis_fraction, axis_value, log_ticks
from volviz.optics.tf_points import MIN_POINTS, insert_point, moved_scalar, remove_point
from . import set_tooltips

GESTURES = ("Click: add a point · drag a point: move it · right-click: remove it · double-click: "
            "change its color")
POINT_RADIUS = 5.0
MARGIN = 8.0
COLOR_BAR_HEIGHT = 18.0


class _SetTransferFunction(QUndoCommand):
    def __init__(self, editor: "TransferFunctionEditor", before: TransferFunction, after: TransferFunction,
                 text: str):
        super().__init__(text)
        self.editor, self.before, self.after = editor, before, after

    def redo(self) -> None:
        self.editor._apply(self.after, commit=True)

    def undo(self) -> None:
        self.editor._apply(self.before, commit=True)


class TransferFunctionCanvas(QWidget):
    """Draws histogram, extinction curve and color bar; lets the user drag, add and remove control points."""

    pointsEdited = Signal()      # while dragging
    editFinished = Signal(str)   # description of a finished edit
    colorRequested = Signal(int)

    def __init__(self, parent: Optional[QWidget] = None):
        super().__init__(parent)
        self.setMinimumSize(260, 160)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.setMouseTracking(True)
        self.scalars = np.array([0.0, 1.0])
        self.colors = np.ones((2, 3))
        self.extinction = np.array([0.0, 1.0])
        self.rho_view = 1.0
        self.histogram: Optional[np.ndarray] = None
        self.histogram_edges: Optional[np.ndarray] = None
        self.log_histogram = False
        self.log_floor: Optional[float] = None    # the scalar axis in log10 from this value (None: linear)
        self.histogram_pending = False  # computed in the background: a placeholder is drawn meanwhile
        self.selected: Optional[int] = None
        self._dragging = False

    # -- geometry ---------------------------------------------------------------------------------------------------
    def _plot_rect(self) -> QRectF:
        return QRectF(MARGIN, MARGIN, self.width() - 2 * MARGIN, self.height() - 3 * MARGIN - COLOR_BAR_HEIGHT)

    def _view_range(self) -> tuple[float, float]:
        lo, hi = float(self.scalars[0]), float(self.scalars[-1])
        if self.histogram_edges is not None:
            lo, hi = min(lo, float(self.histogram_edges[0])), max(hi, float(self.histogram_edges[-1]))
        return (lo, hi if hi > lo else lo + 1.0)

    def x_of(self, s: Any) -> Any:
        """The x pixel of scalar(s) ``s`` (the axis linear, or in log10 with ``log_floor``)."""
        r = self._plot_rect()
        return r.left() + axis_fraction(s, *self._view_range(), self.log_floor) * r.width()

    def to_screen(self, s: float, rho: float) -> QPointF:
        r = self._plot_rect()
        y = r.bottom() - min(rho / self.rho_view, 1.0) * r.height()
        return QPointF(float(self.x_of(s)), y)

    def from_screen(self, point: QPointF) -> tuple[float, float]:
        r = self._plot_rect()
        lo, hi = self._view_range()
        s = float(axis_value((point.x() - r.left()) / max(r.width(), 1.0), lo, hi, self.log_floor))
        rho = (r.bottom() - point.y()) / max(r.height(), 1.0) * self.rho_view
        return (float(np.clip(s, lo, hi)), float(np.clip(rho, 0.0, self.rho_view)))

    def point_at(self, pos: QPointF) -> Optional[int]:
        for i in range(len(self.scalars)):
            p = self.to_screen(self.scalars[i], self.extinction[i])
            if (p - pos).manhattanLength() <= 2.5 * POINT_RADIUS:
                return i
        return None

    # -- painting ---------------------------------------------------------------------------------------------------
    def paintEvent(self, event: Any) -> None:
        painter = QPainter(self)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        painter.fillRect(self.rect(), QColor(36, 36, 40))
        r = self._plot_rect()
        painter.fillRect(r, QColor(24, 24, 28))
        lo, hi = self._view_range()
        if self.histogram_pending:
            painter.setPen(QColor(140, 140, 150))
            painter.drawText(r, Qt.AlignmentFlag.AlignCenter, "computing histogram…")
        elif self.histogram is not None and self.histogram_edges is not None and self.histogram.size:
            counts = np.log1p(self.histogram) if self.log_histogram else self.histogram.astype(np.float64)
            top = counts.max() or 1.0
            painter.setPen(Qt.PenStyle.NoPen)
            painter.setBrush(QColor(90, 90, 100))
            edges = self.histogram_edges
            for c, x0, x1 in zip(counts, self.x_of(edges[:-1]), self.x_of(edges[1:])):
                h = c / top * r.height()
                painter.drawRect(QRectF(x0, r.bottom() - h, max(x1 - x0, 1.0), h))
        if self.log_floor is not None:
            self._paint_log_ticks(painter, r)
        path = QPainterPath()
        for i, (s, rho) in enumerate(zip(self.scalars, self.extinction)):
            p = self.to_screen(s, rho)
            path.moveTo(p) if i == 0 else path.lineTo(p)
        painter.setPen(QPen(QColor(240, 240, 240), 1.5))
        painter.setBrush(Qt.BrushStyle.NoBrush)
        painter.drawPath(path)
        for i, (s, rho) in enumerate(zip(self.scalars, self.extinction)):
            c = self.colors[i]
            painter.setBrush(QColor.fromRgbF(*np.clip(c, 0, 1)))
            painter.setPen(QPen(QColor(255, 220, 0) if i == self.selected else QColor(250, 250, 250), 1.5))
            painter.drawEllipse(self.to_screen(s, rho), POINT_RADIUS, POINT_RADIUS)
        bar = QRectF(r.left(), r.bottom() + MARGIN, r.width(), COLOR_BAR_HEIGHT)
        gradient = QLinearGradient(bar.topLeft(), bar.topRight())
        for f, c in zip(axis_fraction(self.scalars, lo, hi, self.log_floor), self.colors):
            gradient.setColorAt(float(np.clip(f, 0, 1)), QColor.fromRgbF(*np.clip(c, 0, 1)))
        painter.fillRect(bar, QBrush(gradient))
        painter.end()

    def _paint_log_ticks(self, painter: QPainter, r: QRectF) -> None:
        """The log axis's ticks (``log_ticks`` from the floor to the top of the range): a line and its value each."""
        lo, hi = self._view_range()
        floor = max(lo, float(self.log_floor or lo))
        painter.setPen(QPen(QColor(110, 110, 125), 1.0))
        for tick, x in zip(log_ticks(floor, hi), self.x_of(log_ticks(floor, hi))):
            painter.drawLine(QPointF(float(x), r.top()), QPointF(float(x), r.bottom()))
            painter.drawText(QPointF(float(x) + 2.0, r.top() + 11.0), f"{tick:g}")

    # -- interaction ------------------------------------------------------------------------------------------------
    def mousePressEvent(self, event: Any) -> None:
        pos = event.position()
        index = self.point_at(pos)
        if event.button() == Qt.MouseButton.RightButton:
            if index is not None and len(self.scalars) > MIN_POINTS:
                self._remove(index)
                self.editFinished.emit("Remove control point")
            return
        if event.button() != Qt.MouseButton.LeftButton:
            return
        if index is None:
            index = self._insert(*self.from_screen(pos))
            self.pointsEdited.emit()
        self.selected = index
        self._dragging = True
        self.update()

    def mouseMoveEvent(self, event: Any) -> None:
        if not self._dragging or self.selected is None:
            return
        s, rho = self.from_screen(event.position())
        i = self.selected
        self.scalars[i] = moved_scalar(self.scalars, i, s)  # interior points keep their order, the ends the range
        self.extinction[i] = rho
        self.pointsEdited.emit()
        self.update()

    def mouseReleaseEvent(self, event: Any) -> None:
        if self._dragging:
            self._dragging = False
            self.editFinished.emit("Move control point")

    def mouseDoubleClickEvent(self, event: Any) -> None:
        index = self.point_at(event.position())
        if index is not None:
            self.colorRequested.emit(index)

    def _insert(self, s: float, rho: float) -> int:
        self.scalars, self.colors, self.extinction, i = insert_point(self.scalars, self.colors, self.extinction, s,
                                                                     rho)
        return i

    def _remove(self, index: int) -> None:
        self.scalars, self.colors, self.extinction = remove_point(self.scalars, self.colors, self.extinction, index)
        self.selected = None
        self.update()


class TransferFunctionEditor(QWidget):
    """The dock's content: canvas, presets, fit-to-data, log histogram, undo/redo buttons."""

    changed = Signal(object)     # TransferFunction, live while dragging
    committed = Signal(object)   # TransferFunction, after each finished edit (and undo/redo)

    def __init__(self, parent: Optional[QWidget] = None):
        super().__init__(parent)
        self.undo_stack = QUndoStack(self)
        self.canvas = TransferFunctionCanvas(self)
        self._tf = TransferFunction.ramp()
        self._data_range: Optional[tuple[float, float]] = None
        self._committed_tf = self._tf

        self.presets = QComboBox()
        self.presets.addItem("Presets…")
        for name in self._preset_names():
            self.presets.addItem(name)
        self.presets.activated.connect(self._preset_chosen)
        self.fit_button = QPushButton("Fit to data")
        self.fit_button.clicked.connect(self.fit_to_data)
        self.log_box = QCheckBox("Log histogram")
        self.log_box.toggled.connect(self._set_log)
        self.undo_button = QPushButton("Undo")
        self.redo_button = QPushButton("Redo")
        self.undo_button.clicked.connect(self.undo_stack.undo)
        self.redo_button.clicked.connect(self.undo_stack.redo)
        self.undo_stack.canUndoChanged.connect(self.undo_button.setEnabled)
        self.undo_stack.canRedoChanged.connect(self.redo_button.setEnabled)
        self.undo_button.setEnabled(False)
        self.redo_button.setEnabled(False)
        self.import_button = QPushButton("Import…")
        self.export_button = QPushButton("Export…")
        self.import_button.clicked.connect(self._ask_import)
        self.export_button.clicked.connect(self._ask_export)
        self.info = QLabel("")
        self.hint = QLabel(GESTURES)
        self.hint.setWordWrap(True)
        self.hint.setStyleSheet("color: palette(placeholder-text)")
        set_tooltips(
            (self.canvas, GESTURES),
            (self.presets, "Color presets: recolor the function over its range (the opacity curve stays)"),
            (self.fit_button, "Stretch the function over the data's range"),
            (self.log_box, "Draw the histogram on a logarithmic scale (long-tailed data such as CT)"),
            (self.undo_button, "Undo the last transfer-function edit"),
            (self.redo_button, "Redo the transfer-function edit undone last"),
            (self.import_button, "Take the colors from a ParaView color map (JSON)"),
            (self.export_button, "Save the function as a ParaView color map (JSON)"),
        )
        row1 = QHBoxLayout()
        for w in (self.presets, self.fit_button, self.log_box):
            row1.addWidget(w)
        row2 = QHBoxLayout()
        for w in (self.undo_button, self.redo_button, self.import_button, self.export_button):
            row2.addWidget(w)
        layout = QVBoxLayout(self)
        layout.addWidget(self.canvas, 1)
        layout.addLayout(row1)
        layout.addLayout(row2)
        layout.addWidget(self.info)
        layout.addWidget(self.hint)

        self.canvas.pointsEdited.connect(self._canvas_edited)
        self.canvas.editFinished.connect(self._canvas_finished)
        self.canvas.colorRequested.connect(self._pick_color)
        self._load_into_canvas(self._tf)

    # -- public API -------------------------------------------------------------------------------------------------
    @property
    def transfer_function(self) -> TransferFunction:
        return self._tf

    @property
    def committed_transfer_function(self) -> TransferFunction:
        """The function as of the last finished edit (``changed`` with another one: a drag under way)."""
        return self._committed_tf

    def set_transfer_function(self, tf: TransferFunction, data_range: Optional[tuple[float, float]] = None,
                              histogram: Optional[tuple[np.ndarray, np.ndarray]] = None) -> None:
        """Show ``tf`` for a new component (clears undo history)."""
        self.set_histogram(histogram, data_range)
        self.undo_stack.clear()
        self._apply(tf, commit=False)
        self._committed_tf = tf

    def set_log_axis(self, floor: Optional[float]) -> None:
        """Draw the scalar axis in log10 from ``floor`` (the log color scale's smallest positive value; None:
        linear)."""
        self.canvas.log_floor = None if floor is None else float(floor)
        self.canvas.update()

    def set_histogram_pending(self) -> None:
        """The histogram is being computed in the background: a placeholder, no fit to data until it arrives."""
        self.canvas.histogram = self.canvas.histogram_edges = None
        self.canvas.histogram_pending = True
        self._data_range = None
        self.fit_button.setEnabled(False)
        self.canvas.update()

    def set_histogram(self, histogram: Optional[tuple[np.ndarray, np.ndarray]],
                      data_range: Optional[tuple[float, float]]) -> None:
        """Show a histogram computed in the background (None: none) for the TF shown; undo history stays."""
        self.canvas.histogram, self.canvas.histogram_edges = histogram if histogram is not None else (None, None)
        self.canvas.histogram_pending = False
        if histogram is not None:   # long-tailed data (CT's air, a far field) reads better on a log scale
            from volviz.optics.auto_tf import prefers_log_histogram

            self.log_box.setChecked(prefers_log_histogram(histogram[0]))
        self._data_range = data_range
        self.fit_button.setEnabled(True)
        self.canvas.update()

    def edit(self, tf: TransferFunction, text: str) -> None:
        """Replace the transfer function as one undoable edit."""
        self.undo_stack.push(_SetTransferFunction(self, self._committed_tf, tf, text))

    def fit_to_data(self) -> None:
        if self._data_range is not None and self._data_range[1] > self._data_range[0]:
            self.edit(self._tf.rescaled(*self._data_range), "Fit to data range")

    # -- internals --------------------------------------------------------------------------------------------------
    def _apply(self, tf: TransferFunction, commit: bool) -> None:
        self._tf = tf
        self._load_into_canvas(tf)
        if commit:
            self._committed_tf = tf
            self.committed.emit(tf)
        self.changed.emit(tf)

    def _load_into_canvas(self, tf: TransferFunction) -> None:
        c = self.canvas
        c.scalars, c.colors, c.extinction = tf.scalars.copy(), tf.colors.copy(), tf.extinction.copy()
        c.rho_view = max(float(tf.max_extinction) * 1.25, 1e-12)
        c.selected = None
        c.update()
        lo, hi = tf.range
        self.info.setText(f"{tf.name or 'transfer function'}: {len(tf)} points, range {lo:.4g} … {hi:.4g}, "
                          f"ρ max {tf.max_extinction:.3g}")

    def _canvas_tf(self) -> TransferFunction:
        c = self.canvas
        return TransferFunction(c.scalars, c.colors, c.extinction, name=self._tf.name)

    def _canvas_edited(self) -> None:
        try:
            self._tf = self._canvas_tf()
        except ValueError:  # two points momentarily at one scalar: keep the last valid function
            return
        self.changed.emit(self._tf)

    def _canvas_finished(self, text: str) -> None:
        try:
            tf = self._canvas_tf()
        except ValueError:
            tf = self._committed_tf
        self.edit(tf, text)

    def _pick_color(self, index: int) -> None:
        current = QColor.fromRgbF(*np.clip(self.canvas.colors[index], 0, 1))
        color = QColorDialog.getColor(current, self, "Control point color")
        if color.isValid():
            self.set_point_color(index, (color.redF(), color.greenF(), color.blueF()))

    def set_point_color(self, index: int, rgb: tuple[float, float, float]) -> None:
        colors = self._tf.colors.copy()
        colors[index] = rgb
        self.edit(TransferFunction(self._tf.scalars, colors, self._tf.extinction, self._tf.name), "Change color")

    def _set_log(self, on: bool) -> None:
        self.canvas.log_histogram = on
        self.canvas.update()

    @staticmethod
    def _preset_names() -> list[str]:
        try:
            from volviz.optics.presets import list_presets
        except ImportError:
            return []
        return list(list_presets())

    def apply_preset(self, name: str) -> None:
        """Colors from a preset, spread over the current range; the extinction curve is kept."""
        from volviz.optics.presets import load_preset

        preset = load_preset(name)
        self.edit(self._recolor(preset), f"Preset {name}")

    def _recolor(self, source: TransferFunction) -> TransferFunction:
        lo, hi = self._tf.range
        src = source.rescaled(lo, hi)
        colors = np.stack([np.interp(self._tf.scalars, src.scalars, src.colors[:, c]) for c in range(3)], axis=1)
        return TransferFunction(self._tf.scalars, colors, self._tf.extinction, self._tf.name)

    def _preset_chosen(self, index: int) -> None:
        if index > 0:
            self.apply_preset(self.presets.itemText(index))
            self.presets.setCurrentIndex(0)

    def _ask_import(self) -> None:
        path, _ = QFileDialog.getOpenFileName(self, "Import ParaView color map", "", "JSON (*.json)")
        if path:
            self.import_paraview(path)

    def import_paraview(self, path: str) -> bool:
        """Colors from the first preset of a ParaView JSON file; a bad file gives a message, not a crash."""
        from volviz.optics.presets import read_paraview_presets

        try:
            preset = read_paraview_presets(path)[0]
        except ValueError as exc:
            box = QMessageBox(QMessageBox.Icon.Warning, "Cannot import color map", str(exc),
                              QMessageBox.StandardButton.Ok, self)
            box.open()
            self.error_dialog = box
            return False
        self.edit(self._recolor(preset), "Import color map")
        return True

    def _ask_export(self) -> None:
        path, _ = QFileDialog.getSaveFileName(self, "Export ParaView color map", "colormap.json", "JSON (*.json)")
        if path:
            self.export_paraview(path)

    def export_paraview(self, path: str) -> None:
        from volviz.optics.presets import write_paraview_presets

        write_paraview_presets(path, self._tf)
