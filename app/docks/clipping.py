"""Clipping dock: any number of clipping planes (normal + offset) and a box crop for the whole scene (volumes,
isosurfaces and unstructured meshes alike; ``volviz.render.clipping``), with its own undo/redo.

A plane with unit normal n and offset d keeps the points with x·n ≥ d (in the session a
``volviz.model.clip.ClipPlane(point=d·n, normal=n)``). The dock holds the clipping as the session does, an immutable
``ClipSettings``; an edit makes a new one and emits it (``changed``) for ``session.clip``; every edit is one undo
step."""
from __future__ import annotations

import dataclasses
import math
from typing import Any, Optional, Sequence

from PySide6.QtCore import Signal
from PySide6.QtGui import QUndoCommand, QUndoStack
from PySide6.QtWidgets import (QCheckBox, QDoubleSpinBox, QFormLayout, QGroupBox, QListWidget,
                               QPushButton, QVBoxLayout, QWidget)

from volviz.model.clip import BoxCrop, ClipPlane, ClipSettings

from ..widget_row import widget_row
from . import set_tooltips

LIMIT = 1e9


def _spin(decimals: int = 4) -> QDoubleSpinBox:
    box = QDoubleSpinBox()
    box.setRange(-LIMIT, LIMIT)
    box.setDecimals(decimals)
    box.setKeyboardTracking(False)  # typed values apply on Enter / focus out, not per keystroke
    box.setMinimumWidth(64)         # not as wide as the longest value of the range: three fit in a narrow dock
    return box


def plane_offset(plane: ClipPlane) -> tuple[tuple[float, float, float], float]:
    """(unit normal, offset d) of a session plane: it keeps x·n ≥ d."""
    return plane.normal, sum(p * v for p, v in zip(plane.point, plane.normal))


def offset_plane(normal: Sequence[float], offset: float) -> ClipPlane:
    """The plane with normal ``normal`` (made unit length) that keeps x·n ≥ ``offset``."""
    length = math.sqrt(sum(float(v) ** 2 for v in normal))
    if length < 1e-12:
        raise ValueError("a clipping plane needs a non-zero normal")
    n = (float(normal[0]) / length, float(normal[1]) / length, float(normal[2]) / length)
    return ClipPlane((offset * n[0], offset * n[1], offset * n[2]), n)


class _Edit(QUndoCommand):
    def __init__(self, dock: "ClippingDock", before: ClipSettings, after: ClipSettings, text: str):
        super().__init__(text)
        self.dock, self.before, self.after = dock, before, after

    def undo(self) -> None:
        self.dock._apply(self.before)

    def redo(self) -> None:
        self.dock._apply(self.after)


class ClippingDock(QWidget):
    """Edits ``session.clip``; emits ``changed(ClipSettings)``."""

    changed = Signal(object)
    refreshed = Signal()  # the shown planes or the selection changed (the viewport widget follows)

    def __init__(self, parent: Optional[QWidget] = None):
        super().__init__(parent)
        self.clip = ClipSettings()
        self.bounds: tuple[float, ...] = (0.0, 1.0, 0.0, 1.0, 0.0, 1.0)
        self.undo_stack = QUndoStack(self)
        self._loading = False

        self.plane_list = QListWidget()
        self.add_button = QPushButton("Add plane")
        self.remove_button = QPushButton("Remove")
        self.flip_button = QPushButton("Flip")
        self.normal = [_spin() for _ in range(3)]
        self.offset = _spin()
        self.show_widget = QCheckBox("Drag the selected plane and the box in the viewport")
        self.box_enabled = QCheckBox("Box crop")
        self.box_lo = [_spin() for _ in range(3)]
        self.box_hi = [_spin() for _ in range(3)]
        self.undo_button = QPushButton("Undo")
        self.redo_button = QPushButton("Redo")
        self.show_widget.setText("Drag in the viewport")
        set_tooltips(
            (self.show_widget, "Show the selected plane and the box in the viewport, where they can be dragged"),
            (self.plane_list, "The clipping planes; select one to edit it"),
            (self.add_button, "Add a plane through the scene's centre"),
            (self.remove_button, "Remove the selected plane"),
            (self.flip_button, "Keep the other side of the selected plane"),
            (self.offset, "The selected plane keeps the points x with x·n ≥ offset"),
            (self.box_enabled, "Crop the scene to an axis-aligned box"),
            (self.undo_button, "Undo the last clipping edit"),
            (self.redo_button, "Redo the clipping edit undone last"),
            *[(box, f"The {axis} component of the selected plane's normal (it points to the part kept)")
              for box, axis in zip(self.normal, "xyz")],
            *[(box, f"The box's {end} {axis} bound")
              for boxes, end in ((self.box_lo, "lower"), (self.box_hi, "upper")) for box, axis in zip(boxes, "xyz")],
        )

        planes = QGroupBox("Clipping planes (keep x·n ≥ offset)")
        form = QFormLayout(planes)
        form.addRow(self.plane_list)
        form.addRow(widget_row([self.add_button, self.remove_button, self.flip_button]))
        form.addRow("Normal", widget_row(self.normal))
        form.addRow("Offset", self.offset)
        form.addRow(self.show_widget)
        box = QGroupBox("Box")
        box_form = QFormLayout(box)
        box_form.addRow(self.box_enabled)
        box_form.addRow("Min", widget_row(self.box_lo))
        box_form.addRow("Max", widget_row(self.box_hi))
        layout = QVBoxLayout(self)
        layout.addWidget(planes)
        layout.addWidget(box)
        layout.addWidget(widget_row([self.undo_button, self.redo_button]))
        layout.addStretch(1)

        self.add_button.clicked.connect(self.add_plane)
        self.remove_button.clicked.connect(self.remove_plane)
        self.flip_button.clicked.connect(self.flip_plane)
        self.plane_list.currentRowChanged.connect(self._show_plane)
        self.plane_list.currentRowChanged.connect(self._selection_changed)
        for b in self.normal + [self.offset]:
            b.valueChanged.connect(self._plane_edited)
        self.box_enabled.toggled.connect(self._box_edited)
        for b in self.box_lo + self.box_hi:
            b.valueChanged.connect(self._box_edited)
        self.undo_button.clicked.connect(self.undo_stack.undo)
        self.redo_button.clicked.connect(self.undo_stack.redo)
        self.undo_stack.canUndoChanged.connect(self.undo_button.setEnabled)
        self.undo_stack.canRedoChanged.connect(self.redo_button.setEnabled)
        self._refresh()

    # -- public ---------------------------------------------------------------------------------------------------
    def load(self, clip: Optional[ClipSettings], bounds: Optional[Sequence[float]] = None) -> None:
        """Show a session's clipping (no signal, fresh undo history); ``bounds`` (xmin, xmax, ...) of the scene
        place new planes and the default box."""
        if bounds is not None and all(math.isfinite(float(v)) for v in bounds):
            self.bounds = tuple(float(v) for v in bounds)
        self.undo_stack.clear()
        self._apply(ClipSettings() if clip is None else clip, emit=False)

    def add_plane(self) -> None:
        """A new plane through the scene's centre, normal +x."""
        centre = [(self.bounds[2 * k] + self.bounds[2 * k + 1]) / 2.0 for k in range(3)]
        planes = self.clip.planes + (offset_plane((1.0, 0.0, 0.0), centre[0]),)
        self._push(dataclasses.replace(self.clip, planes=planes), "add clipping plane", select=len(planes) - 1)

    def remove_plane(self) -> None:
        row = self.plane_list.currentRow()
        planes = self.clip.planes
        if 0 <= row < len(planes):
            self._push(dataclasses.replace(self.clip, planes=planes[:row] + planes[row + 1:]), "remove clipping plane",
                       select=min(row, len(planes) - 2))

    def flip_plane(self) -> None:
        row = self.plane_list.currentRow()
        if 0 <= row < len(self.clip.planes):
            n, d = plane_offset(self.clip.planes[row])
            self.set_plane(row, [-v for v in n], -d)

    def set_plane(self, index: int, normal: Sequence[float], offset: float) -> None:
        planes = list(self.clip.planes)
        planes[index] = offset_plane(normal, offset)
        self._push(dataclasses.replace(self.clip, planes=tuple(planes)), "edit clipping plane", select=index)

    def set_box(self, lo: Optional[Sequence[float]], hi: Optional[Sequence[float]] = None) -> None:
        """Crop to the box [lo, hi] (None: no box)."""
        top = lo if hi is None else hi
        box = None if lo is None or top is None else BoxCrop((float(lo[0]), float(lo[1]), float(lo[2])),
                                                             (float(top[0]), float(top[1]), float(top[2])))
        self._push(dataclasses.replace(self.clip, box=box), "box crop")

    # -- internals --------------------------------------------------------------------------------------------------
    def _push(self, after: ClipSettings, text: str, select: Optional[int] = None) -> None:
        if after == self.clip:
            return
        self._select = select
        self.undo_stack.push(_Edit(self, self.clip, after, text))

    def _apply(self, clip: ClipSettings, emit: bool = True) -> None:
        self.clip = clip
        self._refresh()
        if emit:
            self.changed.emit(self.clip)

    def _refresh(self) -> None:
        self._loading = True
        row = getattr(self, "_select", None)
        if row is None:
            row = self.plane_list.currentRow()
        self._select = None
        self.plane_list.clear()
        for i, p in enumerate(self.clip.planes):
            n, d = plane_offset(p)
            self.plane_list.addItem(f"plane {i + 1}: n = ({n[0]:.2f}, {n[1]:.2f}, {n[2]:.2f}), offset {d:.3g}")
        count = len(self.clip.planes)
        self.plane_list.setCurrentRow(min(max(row, 0), count - 1) if count else -1)
        self._show_plane(self.plane_list.currentRow())
        box = self.clip.box
        self.box_enabled.setChecked(box is not None)
        lo = box.lo if box else self.bounds[0::2]
        hi = box.hi if box else self.bounds[1::2]
        for b, v in zip(self.box_lo + self.box_hi, list(lo) + list(hi)):
            b.setValue(float(v))
            b.setEnabled(box is not None)
        self.undo_button.setEnabled(self.undo_stack.canUndo())
        self.redo_button.setEnabled(self.undo_stack.canRedo())
        self._loading = False
        self.refreshed.emit()

    def _show_plane(self, row: int) -> None:
        loading, self._loading = self._loading, True
        has = 0 <= row < len(self.clip.planes)
        n, d = plane_offset(self.clip.planes[row]) if has else ((1.0, 0.0, 0.0), 0.0)
        for b, v in zip(self.normal, n):
            b.setValue(v)
            b.setEnabled(has)
        self.offset.setValue(d)
        self.offset.setEnabled(has)
        self.remove_button.setEnabled(has)
        self.flip_button.setEnabled(has)
        self._loading = loading

    def _selection_changed(self, row: int) -> None:
        if not self._loading:
            self.refreshed.emit()

    def _plane_edited(self, *args: Any) -> None:
        row = self.plane_list.currentRow()
        if self._loading or not 0 <= row < len(self.clip.planes):
            return
        normal = [b.value() for b in self.normal]
        if math.sqrt(sum(v * v for v in normal)) < 1e-12:
            return  # a zero normal is not a plane: wait for the next component
        self.set_plane(row, normal, self.offset.value())

    def _box_edited(self, *args: Any) -> None:
        if self._loading:
            return
        if not self.box_enabled.isChecked():
            self.set_box(None)
            return
        lo = [b.value() for b in self.box_lo]
        hi = [max(b.value(), l) for b, l in zip(self.box_hi, lo)]
        self.set_box(lo, hi)
