"""The Slices dock: a row per axis (a check box to show the plane x, y or z, a slider and a spin box for its grid
index) and the three slices as 2D images, each pixel one grid sample (drawn at a whole-number zoom, without
smoothing, so a pixel on screen is a sample's colour). The window's slice tool (``volviz_app.slice_tool``) turns
the signals into scene edits and gives the dock the images (``volviz.render.slices.slice_image``)."""
from __future__ import annotations

from typing import Any, Optional

from PySide6.QtCore import QRect, Qt, Signal
from PySide6.QtGui import QImage, QPainter
from PySide6.QtWidgets import (QCheckBox, QGridLayout, QHBoxLayout, QLabel, QSlider, QSpinBox, QVBoxLayout,
                               QWidget)

AXES = ("x", "y", "z")
VIEW_SIZE = 150   # pixels: the largest side of a 2D slice view


class SliceImage(QWidget):
    """One slice as an image: ``zoom`` screen pixels per sample, nearest-neighbour, painted from the 8-bit image
    itself (not a pixmap of the screen's depth: on a 16-bit display a pixmap would round the colours)."""

    def __init__(self, axis: str) -> None:
        super().__init__()
        self.axis, self.zoom = axis, 1
        self.image: Optional[QImage] = None
        self.setMinimumSize(VIEW_SIZE // 2, VIEW_SIZE // 2)
        self.setToolTip(f"the {axis} slice")

    def show_rgb(self, rgb: Any) -> None:
        """Show a (rows, cols, 3) uint8 image (None: nothing)."""
        if rgb is None:
            self.image = None
        else:
            rows, cols = int(rgb.shape[0]), int(rgb.shape[1])
            self.image = QImage(rgb.tobytes(), cols, rows, 3 * cols, QImage.Format.Format_RGB888).copy()
            self.zoom = max(1, VIEW_SIZE // max(rows, cols))
            self.setMinimumSize(cols * self.zoom, rows * self.zoom)
        self.update()

    def paintEvent(self, event: Any) -> None:  # noqa: N802  (Qt's name)
        if self.image is None:
            return
        painter = QPainter(self)
        painter.setRenderHint(QPainter.RenderHint.SmoothPixmapTransform, False)
        painter.drawImage(QRect(0, 0, self.image.width() * self.zoom, self.image.height() * self.zoom), self.image)
        painter.end()


class SlicesDock(QWidget):
    """Check boxes, sliders and 2D views of the three slices (module docstring). ``changed(axis, index)``: the user
    moved or toggled a plane (index None: off)."""

    changed = Signal(str, object)

    def __init__(self, parent: Optional[QWidget] = None) -> None:
        super().__init__(parent)
        self.checks: dict[str, QCheckBox] = {}
        self.sliders: dict[str, QSlider] = {}
        self.spins: dict[str, QSpinBox] = {}
        self.views: dict[str, SliceImage] = {}
        grid = QGridLayout()
        for row, axis in enumerate(AXES):
            check = QCheckBox(axis.upper())
            slider = QSlider(Qt.Orientation.Horizontal)
            spin = QSpinBox()
            slider.valueChanged.connect(spin.setValue)
            spin.valueChanged.connect(slider.setValue)
            spin.valueChanged.connect(lambda _v, a=axis: self._moved(a))
            check.toggled.connect(lambda _on, a=axis: self._moved(a))
            check.setToolTip(f"Show the plane {axis} = const in the 3D view and below")
            slider.setToolTip(f"Move the {axis} plane (grid index)")
            spin.setToolTip(f"Grid index of the {axis} plane")
            grid.addWidget(check, row, 0)
            grid.addWidget(slider, row, 1)
            grid.addWidget(spin, row, 2)
            self.checks[axis], self.sliders[axis], self.spins[axis] = check, slider, spin
        images = QHBoxLayout()
        for axis in AXES:
            self.views[axis] = SliceImage(axis)
            images.addWidget(self.views[axis])
        self.note = QLabel("")
        self.note.setWordWrap(True)
        layout = QVBoxLayout(self)
        layout.addLayout(grid)
        layout.addLayout(images)
        layout.addWidget(self.note)
        layout.addStretch(1)
        self._filling = False
        self.set_extent(None)

    def _moved(self, axis: str) -> None:
        if not self._filling:
            self.changed.emit(axis, self.index(axis))

    def index(self, axis: str) -> Optional[int]:
        """The plane's index, None when it is off."""
        return self.spins[axis].value() if self.checks[axis].isChecked() else None

    def set_extent(self, dims: Optional[tuple[int, int, int]], note: str = "") -> None:
        """The grid's samples per axis (None: no regular volume to slice; ``note`` says why)."""
        self._filling = True
        try:
            for i, axis in enumerate(AXES):
                top = (dims[i] - 1) if dims else 0
                self.sliders[axis].setRange(0, top)
                self.spins[axis].setRange(0, top)
                for widget in (self.checks[axis], self.sliders[axis], self.spins[axis]):
                    widget.setEnabled(dims is not None)
                if dims is None:
                    self.checks[axis].setChecked(False)
                    self.views[axis].show_rgb(None)
        finally:
            self._filling = False
        self.note.setText(note)

    def set_state(self, indices: dict[str, Optional[int]]) -> None:
        """Show the planes ``indices`` (axis -> index, None: off) without emitting ``changed``."""
        self._filling = True
        try:
            for axis in AXES:
                index = indices.get(axis)
                self.checks[axis].setChecked(index is not None)
                if index is not None:
                    self.spins[axis].setValue(int(index))
        finally:
            self._filling = False
