"""File > Open of headerless binary data (a ``.raw`` file without a header, a stack of numbered slices such as
``quarter.1`` ... ``quarter.93``): instead of an error asking for a hand-written header, a dialog with volviz's
guess of the layout (``volviz.io.raw_layout``: sizes, sample type, byte order, header bytes), the other guesses, a
preview of the middle slice that follows every change, and the voxel spacing the file cannot know. Open writes the
layout down as a MetaImage header beside the data (or in volviz's own data folder where the data's folder is
read-only) and opens that header: the data then opens directly next time, and sessions refer to the header."""
from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Any, Callable, Optional, Sequence

from PySide6.QtCore import QStandardPaths, Qt
from PySide6.QtGui import QImage, QPixmap
from PySide6.QtWidgets import (QComboBox, QDialog, QDialogButtonBox, QDoubleSpinBox, QFormLayout, QLabel, QSpinBox,
                               QVBoxLayout, QWidget)

from volviz.io.raw_layout import (SAMPLE_TYPES, RawLayout, guess_layouts, layout_problem, layout_slice,
                                  preview_image, write_header)
from .widget_row import widget_row

PREVIEW_PIXELS = 220


def header_folder() -> Path:
    """Where headers go when the data's own folder is read-only."""
    return Path(QStandardPaths.writableLocation(QStandardPaths.StandardLocation.AppDataLocation)) / "raw-headers"


class RawImportDialog(QDialog):
    """The layout of ``files`` (one file, or a stack's slices in order); ``opened(header_path)`` is called with the
    header written on Open."""

    def __init__(self, files: Sequence[Path], opened: Callable[[Path], None], parent: Optional[QWidget] = None,
                 guesses: Optional[list[RawLayout]] = None) -> None:
        super().__init__(parent)
        self.files, self.opened = list(files), opened
        self.guesses = guesses if guesses is not None else guess_layouts(self.files)
        stack = len(self.files) > 1
        self.setWindowTitle(f"Open raw data: {self.files[0].name}" + (f" and {len(self.files) - 1} more slices"
                                                                      if stack else ""))
        self.choice = QComboBox()
        for layout in self.guesses:
            self.choice.addItem(self.describe(layout))
        self.sizes = [self._spin(1, 1 << 20) for _ in range(3)]
        self.sizes[2].setEnabled(not stack)                     # a stack's depth is its number of files
        self.dtype = QComboBox()
        self.dtype.addItems(list(SAMPLE_TYPES))
        self.order = QComboBox()
        self.order.addItems(["little", "big"])
        self.header = self._spin(0, 1 << 30)
        self.spacing = [QDoubleSpinBox() for _ in range(3)]
        for box in self.spacing:
            box.setDecimals(4)
            box.setRange(1e-4, 1e6)
            box.setValue(1.0)
        self.problem = QLabel()
        self.problem.setWordWrap(True)
        self.preview = QLabel()
        self.preview.setFixedSize(PREVIEW_PIXELS, PREVIEW_PIXELS)
        self.preview.setAlignment(Qt.AlignmentFlag.AlignCenter)
        form = QFormLayout()
        form.addRow("Guess", self.choice)
        form.addRow("Size x, y, z", widget_row(self.sizes))
        form.addRow("Sample type", self.dtype)
        form.addRow("Byte order", self.order)
        form.addRow("Header bytes" + (" per slice" if stack else ""), self.header)
        form.addRow("Spacing x, y, z", widget_row(self.spacing))
        self.buttons = QDialogButtonBox(QDialogButtonBox.StandardButton.Open | QDialogButtonBox.StandardButton.Cancel)
        self.buttons.accepted.connect(self.accept)
        self.buttons.rejected.connect(self.reject)
        body = QVBoxLayout(self)
        intro = QLabel("volviz guessed how the data is laid out from its bytes; check the preview, correct what is "
                       "wrong and set the voxel spacing. A header is written beside the data so that it opens "
                       "directly next time.")
        intro.setWordWrap(True)
        body.addWidget(intro)
        body.addLayout(form)
        body.addWidget(self.preview, alignment=Qt.AlignmentFlag.AlignHCenter)
        body.addWidget(self.problem)
        body.addWidget(self.buttons)
        self.choice.currentIndexChanged.connect(self.apply_guess)
        for widget in (*self.sizes, self.header):
            widget.valueChanged.connect(self.refresh)
        for combo in (self.dtype, self.order):
            combo.currentIndexChanged.connect(self.refresh)
        self.apply_guess(0)
        self.resize(520, self.sizeHint().height())

    @staticmethod
    def _spin(lo: int, hi: int) -> QSpinBox:
        box = QSpinBox()
        box.setRange(lo, hi)
        return box

    @staticmethod
    def describe(layout: RawLayout) -> str:
        order = f", {layout.byteorder} endian" if layout.itemsize > 1 else ""
        header = f", {layout.header_bytes}-byte header" if layout.header_bytes else ""
        return f"{' x '.join(map(str, layout.dims))} {layout.dtype}{order}{header}"

    def apply_guess(self, index: int) -> None:
        """Fill the fields with guess ``index``."""
        if not 0 <= index < len(self.guesses):
            return
        layout = self.guesses[index]
        widgets: list[Any] = [*self.sizes, self.header, self.dtype, self.order]
        for widget in widgets:
            widget.blockSignals(True)
        for box, n in zip(self.sizes, layout.dims):
            box.setValue(n)
        self.header.setValue(layout.header_bytes)
        self.dtype.setCurrentText(layout.dtype)
        self.order.setCurrentText(layout.byteorder)
        for widget in widgets:
            widget.blockSignals(False)
        self.refresh()

    def layout(self) -> RawLayout:  # type: ignore[override]  # QWidget.layout() is not used on this dialog
        return RawLayout(tuple(box.value() for box in self.sizes),  # type: ignore[arg-type]
                         self.dtype.currentText(), self.order.currentText(), self.header.value())

    def refresh(self) -> None:
        """The fields' layout checked against the files, and its middle slice shown."""
        layout = self.layout()
        problem = layout_problem(self.files, layout)
        self.problem.setText(problem or f"{self.describe(layout)}: fits the data.")
        self.problem.setStyleSheet("color: #c0392b;" if problem else "")
        self.buttons.button(QDialogButtonBox.StandardButton.Open).setEnabled(problem is None)
        if problem is not None:
            self.preview.setText("no preview")
            return
        grey = preview_image(layout_slice(self.files, layout, layout.dims[2] // 2))
        rows, cols = grey.shape
        image = QImage(grey.data, cols, rows, cols, QImage.Format.Format_Grayscale8).copy()
        self.preview.setPixmap(QPixmap.fromImage(image).scaled(
            PREVIEW_PIXELS, PREVIEW_PIXELS, Qt.AspectRatioMode.KeepAspectRatio,
            Qt.TransformationMode.SmoothTransformation))

    def accept(self) -> None:
        layout = self.layout()
        if layout_problem(self.files, layout) is not None:
            return
        spacing = [box.value() for box in self.spacing]
        header = write_header(self.files, replace(layout, score=0.0), spacing, header_folder())
        super().accept()
        self.opened(header)
