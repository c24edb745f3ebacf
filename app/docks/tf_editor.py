"""Transfer-function editor dock: extinction curve with draggable control points over the data histogram, color
stops with a color picker, presets (ParaView JSON import/export), fit to data range, undo/redo.

The editor holds a ``TransferFunction`` (volviz.optics) and never computes optics itself; where a point goes when
one is added, moved or removed is ``volviz.optics.tf_points``. It emits ``changed(tf)`` continuously while the user
drags (the window throttles re-rendering) and ``committed(tf)`` when an edit is finished; each finished edit is one
entry of the undo stack. With the component's log color scale on (``set_log_axis``), the scalar axis is in log10
from the scale's smallest positive value, with its ticks labelled, so the color bar reads as the volume is colored
(``volviz.optics.log_scale``). The canvas that draws the histogram, the curve and the color bar and takes the
mouse is ``tf_canvas``; this module wires it to the buttons, the undo stack and the presets.
"""
from __future__ import annotations

from typing import Optional

import numpy as np
from PySide6.QtCore import Signal
from PySide6.QtGui import QColor, QUndoCommand, QUndoStack
from PySide6.QtWidgets import (QCheckBox, QColorDialog, QComboBox, QFileDialog, QHBoxLayout, QLabel, QMessageBox,
                               QPushButton, QVBoxLayout, QWidget)

from volviz.optics import TransferFunction
from volviz.optics.auto_tf import prefers_log_histogram
from volviz.optics.presets import list_presets, load_preset, read_paraview_presets, write_paraview_presets
from . import set_tooltips
from .tf_canvas import GESTURES, TransferFunctionCanvas


class _SetTransferFunction(QUndoCommand):
    def __init__(self, editor: "TransferFunctionEditor", before: TransferFunction, after: TransferFunction,
                 text: str):
        super().__init__(text)
        self.editor, self.before, self.after = editor, before, after

    def redo(self) -> None:
        self.editor._apply(self.after, commit=True)

    def undo(self) -> None:
        self.editor._apply(self.before, commit=True)


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
            self.log_box.setChecked(prefers_log_histogram(histogram[0]))
        self._data_range = data_range
        self.fit_button.setEnabled(True)
        self.canvas.update()

    def edit(self, tf: TransferFunction, text: str) -> None:
        """Replace the transfer function as one undoable edit."""
        self.undo_stack.push(_SetTransferFunction(self, self._committed_tf, tf, text))

    def follow(self, tf: TransferFunction) -> None:
        """The shown component's function was set elsewhere (a script in the Python console): show it as one
        undoable edit, not emitted again (the session holds it). Without this the dock kept the old function, and the
        next drag of a point put the old colors back (issue #28)."""
        if tf is self._tf or tf is self._committed_tf:
            return
        self.blockSignals(True)
        try:
            self.edit(tf, "Set from outside the editor")
        finally:
            self.blockSignals(False)

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
        return list(list_presets())

    def apply_preset(self, name: str) -> None:
        """Colors from a preset, spread over the current range; the extinction curve is kept."""
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
        write_paraview_presets(path, self._tf)
