"""The editors of a settings form (``settings_form``): one widget per field type of a settings model, each with the
value it shows and a callback on each committed change, and the helpers that read a pydantic field's bounds, hints
and default. Split from the form so each module has one purpose: these know widgets and fields, the form knows rows,
ticks and the model's verdict.
"""
from __future__ import annotations

import copy
import json
import typing
from typing import Any, Callable, Generic, Literal, Optional, Sequence, TypeVar, Union

from pydantic.fields import FieldInfo
from PySide6.QtCore import Signal
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (QAbstractSpinBox, QCheckBox, QColorDialog, QComboBox, QDoubleSpinBox, QHBoxLayout,
                               QHeaderView, QLabel, QPushButton, QSpinBox, QTableWidget, QVBoxLayout, QWidget)

from volviz.model.settings import IsoStyleSettings

__all__ = ["ColorButton", "Editor", "FloatBox", "StylesTable", "editor_for", "field_bounds", "field_default", "plain"]

DECIMALS = 6                      # digits after the point a float spin box keeps (trailing zeros are not shown)
FLOAT_LIMIT = 1e9                 # the range of a float field without bounds
INT_LIMIT = 2 ** 31 - 1           # the range of an int field without bounds (QSpinBox holds a C int)
CLIP_NOTE = "Edited in the Clipping dock"

_W = TypeVar("_W", bound=QWidget, covariant=True)  # an editor's widget
_Cell = TypeVar("_Cell", bound=QWidget)


def field_bounds(info: FieldInfo) -> tuple[Optional[float], Optional[float]]:
    """The (lower, upper) bounds of a field (ge / gt, le / lt), None where it has none."""
    lower = upper = None
    for item in info.metadata:
        for name in ("ge", "gt"):
            if getattr(item, name, None) is not None:
                lower = getattr(item, name)
        for name in ("le", "lt"):
            if getattr(item, name, None) is not None:
                upper = getattr(item, name)
    return lower, upper


def field_hints(info: FieldInfo) -> dict[str, Any]:
    return info.json_schema_extra if isinstance(info.json_schema_extra, dict) else {}


def without_none(annotation: Any) -> Any:
    """``X`` for ``Optional[X]``; the annotation itself otherwise."""
    if typing.get_origin(annotation) is typing.Union:
        args = [a for a in typing.get_args(annotation) if a is not type(None)]
        if len(args) == 1:
            return args[0]
    return annotation


def field_default(info: FieldInfo) -> Any:
    """The model's default of a field (None for a required one)."""
    if info.default_factory is not None:
        return info.default_factory()  # type: ignore[call-arg]
    return None if info.is_required() else copy.deepcopy(info.default)


def plain(value: Any) -> Any:
    """A value as a session stores it (lists, not tuples)."""
    if isinstance(value, (tuple, list)):
        return [plain(v) for v in value]
    if isinstance(value, dict):
        return {k: plain(v) for k, v in value.items()}
    return value


class FloatBox(QDoubleSpinBox):
    """A double spin box with ``DECIMALS`` digits that shows no trailing zeros, stepping by the value's magnitude, and
    reporting a value once it is entered (not per key typed)."""

    def __init__(self, parent: Optional[QWidget] = None) -> None:
        super().__init__(parent)
        self.setDecimals(DECIMALS)
        self.setStepType(QAbstractSpinBox.StepType.AdaptiveDecimalStepType)
        self.setKeyboardTracking(False)

    def textFromValue(self, value: float) -> str:
        text = self.locale().toString(value, "f", self.decimals())
        point = self.locale().decimalPoint()
        return text.rstrip("0").rstrip(point) if point in text else text


def number_box(annotation: Any, info: Optional[FieldInfo] = None) -> Union[QSpinBox, FloatBox]:
    """A spin box for an int or float with the field's bounds (the whole range where it has none) and unit."""
    if annotation is not int:
        return float_box(info)
    lower, upper = field_bounds(info) if info is not None else (None, None)
    box = QSpinBox()
    box.setKeyboardTracking(False)
    box.setRange(int(lower) if lower is not None else -INT_LIMIT, int(upper) if upper is not None else INT_LIMIT)
    show_unit(box, info)
    return box


def float_box(info: Optional[FieldInfo] = None) -> FloatBox:
    """A spin box for a float with the field's bounds (the whole range where it has none) and unit."""
    lower, upper = field_bounds(info) if info is not None else (None, None)
    box = FloatBox()
    box.setRange(float(lower) if lower is not None else -FLOAT_LIMIT,
                 float(upper) if upper is not None else FLOAT_LIMIT)
    show_unit(box, info)
    return box


def show_unit(box: Union[QSpinBox, FloatBox], info: Optional[FieldInfo]) -> None:
    unit = field_hints(info).get("unit") if info is not None else None
    if unit:
        box.setSuffix(f" {unit}")


class ColorButton(QPushButton):
    """A button showing an RGB color (components 0..1); clicking it opens a color dialog (``dialog``), and a color
    chosen there is shown and reported by ``chosen``."""

    chosen = Signal()

    def __init__(self, parent: Optional[QWidget] = None) -> None:
        super().__init__(parent)
        self.rgb: tuple[float, float, float] = (1.0, 1.0, 1.0)
        self.dialog: Optional[QColorDialog] = None
        self.clicked.connect(self._pick)

    def set_rgb(self, rgb: Sequence[float]) -> None:
        self.rgb = (float(rgb[0]), float(rgb[1]), float(rgb[2]))
        color = QColor.fromRgbF(*self.rgb)
        self.setText(color.name())
        text = "black" if color.lightnessF() > 0.5 else "white"
        self.setStyleSheet(f"background-color: {color.name()}; color: {text}")

    def _pick(self) -> None:
        self.dialog = QColorDialog(QColor.fromRgbF(*self.rgb), self)
        self.dialog.colorSelected.connect(self._chosen)
        self.dialog.open()

    def _chosen(self, color: QColor) -> None:
        self.set_rgb((color.redF(), color.greenF(), color.blueF()))
        self.chosen.emit()


class Editor(Generic[_W]):
    """The editor of one field: ``widget``, ``value()`` (as the session stores it) and ``show(value)`` (no report);
    ``edited`` is called when the user committed a value."""

    def __init__(self, widget: _W, edited: Callable[[], None]) -> None:
        self.widget, self.edited = widget, edited

    def value(self) -> Any:
        raise NotImplementedError

    def show(self, value: Any) -> None:
        raise NotImplementedError


class CheckBoxEditor(Editor[QCheckBox]):
    def __init__(self, edited: Callable[[], None]) -> None:
        super().__init__(QCheckBox(), edited)
        self.widget.toggled.connect(lambda _on: self.edited())

    def value(self) -> bool:
        return self.widget.isChecked()

    def show(self, value: Any) -> None:
        self.widget.blockSignals(True)
        self.widget.setChecked(bool(value))
        self.widget.blockSignals(False)


class ChoiceEditor(Editor[QComboBox]):
    """A combo box of fixed choices (a ``Literal``) or of names (datasets, arrays): None is no entry chosen."""

    def __init__(self, choices: Sequence[str], edited: Callable[[], None]) -> None:
        super().__init__(QComboBox(), edited)
        self.widget.addItems([str(c) for c in choices])
        self.widget.currentIndexChanged.connect(lambda _index: self.edited())

    def value(self) -> Optional[str]:
        return self.widget.currentText() if self.widget.currentIndex() >= 0 else None

    def show(self, value: Any) -> None:
        self.widget.blockSignals(True)
        if value is not None and self.widget.findText(str(value)) < 0:
            self.widget.addItem(str(value))  # a name the session gives that is not (or no longer) offered
        self.widget.setCurrentIndex(-1 if value is None else self.widget.findText(str(value)))
        self.widget.blockSignals(False)


class NumberEditor(Editor[Union[QSpinBox, FloatBox]]):
    def __init__(self, annotation: Any, info: FieldInfo, edited: Callable[[], None]) -> None:
        super().__init__(number_box(annotation, info), edited)
        self.kind = annotation
        self.widget.editingFinished.connect(self.edited)

    def value(self) -> Any:
        return self.kind(self.widget.value())

    def show(self, value: Any) -> None:
        self.widget.blockSignals(True)
        self.widget.setValue(self.kind(self.widget.minimum()) if value is None else value)
        self.widget.blockSignals(False)


class VectorEditor(Editor[QWidget]):
    """A row of spin boxes for a fixed-length tuple (extent, origin, grid shape)."""

    def __init__(self, kinds: Sequence[Any], info: FieldInfo, edited: Callable[[], None]) -> None:
        super().__init__(QWidget(), edited)
        row = QHBoxLayout(self.widget)
        row.setContentsMargins(0, 0, 0, 0)
        unit = field_hints(info).get("unit")
        self.kinds = list(kinds)
        self.boxes: list[Union[QSpinBox, FloatBox]] = []
        for kind in self.kinds:
            box = number_box(kind)
            if unit:
                box.setSuffix(f" {unit}")
            box.editingFinished.connect(self.edited)
            row.addWidget(box)
            self.boxes.append(box)

    def value(self) -> list[Any]:
        return [kind(box.value()) for kind, box in zip(self.kinds, self.boxes)]

    def show(self, value: Any) -> None:
        for i, box in enumerate(self.boxes):
            box.blockSignals(True)
            box.setValue(0 if value is None else value[i])
            box.blockSignals(False)


class ColorEditor(Editor[ColorButton]):
    def __init__(self, edited: Callable[[], None]) -> None:
        super().__init__(ColorButton(), edited)
        self.widget.chosen.connect(self.edited)

    def value(self) -> list[float]:
        return list(self.widget.rgb)

    def show(self, value: Any) -> None:
        self.widget.set_rgb(value if value is not None else (1.0, 1.0, 1.0))


class ReadOnlyEditor(Editor[QLabel]):
    """A nested object without a model (the isosurfaces' clipping): shown as JSON, edited elsewhere."""

    def __init__(self, note: str) -> None:
        super().__init__(QLabel(), lambda: None)
        self.note, self._value = note, None
        self.widget.setWordWrap(True)

    def value(self) -> Any:
        return copy.deepcopy(self._value)

    def show(self, value: Any) -> None:
        self._value = copy.deepcopy(value)
        self.widget.setText(f"{json.dumps(value)}\n({self.note})")


class StylesTable(QWidget):
    """The isosurfaces' ``styles``: a table of surfaces (iso-value, color, opacity) with Add and Remove buttons;
    ``edited`` reports a committed change."""

    edited = Signal()

    def __init__(self, parent: Optional[QWidget] = None) -> None:
        super().__init__(parent)
        fields = IsoStyleSettings.model_fields
        self.table = QTableWidget(0, 3)
        self.table.setHorizontalHeaderLabels([fields[name].title or name for name in ("value", "color", "opacity")])
        self.table.horizontalHeader().setSectionResizeMode(QHeaderView.ResizeMode.Stretch)
        self.table.verticalHeader().setVisible(False)
        self.add_button = QPushButton("Add surface")
        self.remove_button = QPushButton("Remove surface")
        self.add_button.setToolTip("Add a surface after the selected one (or the last), with its value")
        self.remove_button.setToolTip("Remove the selected surface (or the last)")
        self.add_button.clicked.connect(self.add_surface)
        self.remove_button.clicked.connect(self.remove_surface)
        buttons = QHBoxLayout()
        buttons.addWidget(self.add_button)
        buttons.addWidget(self.remove_button)
        layout = QVBoxLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.addWidget(self.table)
        layout.addLayout(buttons)

    def styles(self) -> list[dict[str, Any]]:
        """The surfaces as the session stores them."""
        return [{"value": self._cell(row, 0, FloatBox).value(), "color": list(self._cell(row, 1, ColorButton).rgb),
                 "opacity": self._cell(row, 2, FloatBox).value()} for row in range(self.table.rowCount())]

    def _cell(self, row: int, column: int, kind: type[_Cell]) -> _Cell:
        """The editor in a cell of the table (``_append`` put it there)."""
        widget = self.table.cellWidget(row, column)
        if not isinstance(widget, kind):
            raise TypeError(f"the cell ({row}, {column}) of the surfaces table holds no {kind.__name__}")
        return widget

    def set_styles(self, styles: Sequence[dict[str, Any]]) -> None:
        """Show ``styles`` (a missing color or opacity as the model's default), reporting nothing."""
        self.table.setRowCount(0)
        for style in styles:
            self._append(style)
        self.remove_button.setEnabled(self.table.rowCount() > 0)

    def _append(self, style: dict[str, Any], row: Optional[int] = None) -> None:
        fields = IsoStyleSettings.model_fields
        row = self.table.rowCount() if row is None else row
        self.table.insertRow(row)
        value = float_box(fields["value"])
        value.setValue(float(style.get("value", 0.0)))
        color = ColorButton()
        color.set_rgb(style.get("color", field_default(fields["color"])))
        opacity = float_box(fields["opacity"])
        opacity.setValue(float(style.get("opacity", field_default(fields["opacity"]))))
        for column, widget in enumerate((value, color, opacity)):
            widget.setToolTip(fields[("value", "color", "opacity")[column]].title or "")
            self.table.setCellWidget(row, column, widget)
        value.editingFinished.connect(self.edited)
        opacity.editingFinished.connect(self.edited)
        color.chosen.connect(self.edited)

    def add_surface(self) -> None:
        """A new surface after the selected one (or the last), a copy of it; reported as an edit."""
        rows = self.table.rowCount()
        at = self.table.currentRow() if self.table.currentRow() >= 0 else rows - 1
        style = self.styles()[at] if rows else {"value": 0.0}
        self._append(style, at + 1)
        self.remove_button.setEnabled(True)
        self.edited.emit()

    def remove_surface(self) -> None:
        """Remove the selected surface (or the last); reported as an edit."""
        rows = self.table.rowCount()
        if rows:
            self.table.removeRow(self.table.currentRow() if self.table.currentRow() >= 0 else rows - 1)
            self.remove_button.setEnabled(self.table.rowCount() > 0)
            self.edited.emit()


class StylesEditor(Editor[StylesTable]):
    def __init__(self, edited: Callable[[], None]) -> None:
        super().__init__(StylesTable(), edited)
        self.widget.edited.connect(self.edited)

    def value(self) -> list[dict[str, Any]]:
        return self.widget.styles()

    def show(self, value: Any) -> None:
        self.widget.set_styles(value or [])


def editor_for(name: str, info: FieldInfo, datasets: Sequence[str], arrays: Callable[[], Sequence[str]],
               edited: Callable[[], None]) -> Editor[QWidget]:
    """The editor of field ``name``, chosen by its type and hints (see the module docstring of
    ``settings_form``); ``edited`` is called on each committed change."""
    hints, annotation = field_hints(info), without_none(info.annotation)
    origin = typing.get_origin(annotation)
    if hints.get("color"):
        return ColorEditor(edited)
    if hints.get("dataset"):
        return ChoiceEditor(datasets, edited)
    if hints.get("array"):
        return ChoiceEditor(arrays(), edited)
    if annotation is bool:
        return CheckBoxEditor(edited)
    if origin is Literal:
        return ChoiceEditor(typing.get_args(annotation), edited)
    if annotation in (int, float):
        return NumberEditor(annotation, info, edited)
    if origin is tuple:
        return VectorEditor(typing.get_args(annotation), info, edited)
    if origin is list and typing.get_args(annotation) == (IsoStyleSettings,):
        return StylesEditor(edited)
    return ReadOnlyEditor(CLIP_NOTE if name == "clip" else "not editable here")
