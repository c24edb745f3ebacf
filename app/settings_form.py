"""A component's settings as a form generated from its typed settings model (``volviz.model.settings``).

One row per field of the model: its title as the label, its description as the tooltip, and an editor chosen by the
field's type: a check box (bool), a combo box of the choices (``Literal``), a spin box with the field's bounds and
unit (int, float), a row of spin boxes (fixed-length tuples), a color button (``{"color": True}``), a combo box of
the session's datasets (``{"dataset": True}``) or of the dataset's arrays (``{"array": True}``), a table of surfaces
(the isosurfaces' ``styles``); a nested object without a model (the isosurfaces' clipping) is shown read-only.

A field the session sets has its label ticked; unticking it removes the key, so the model's default applies again
(sessions store only the settings that were set). Every committed edit (a spin box's editing finished, a combo box's
or check box's change, a color chosen) is checked with ``typed_settings`` first: a refused value shows the problem
next to its field and changes nothing; an accepted one is emitted as the whole new settings dict (``committed``).
"""
from __future__ import annotations

import copy
import json
import typing
from typing import Any, Callable, Generic, Literal, Optional, Sequence, TypeVar, Union

from pydantic.fields import FieldInfo
from PySide6.QtCore import Signal
from PySide6.QtGui import QColor
from PySide6.QtWidgets import (QAbstractSpinBox, QCheckBox, QColorDialog, QComboBox, QDoubleSpinBox, QFormLayout,
                               QHBoxLayout, QHeaderView, QLabel, QPushButton, QSpinBox, QTableWidget, QVBoxLayout,
                               QWidget)

from volviz.model.settings import IsoStyleSettings, SettingsError, settings_model, typed_settings

__all__ = ["SettingsForm", "ColorButton", "FloatBox", "StylesTable", "field_bounds"]

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


def _hints(info: FieldInfo) -> dict[str, Any]:
    return info.json_schema_extra if isinstance(info.json_schema_extra, dict) else {}


def _without_none(annotation: Any) -> Any:
    """``X`` for ``Optional[X]``; the annotation itself otherwise."""
    if typing.get_origin(annotation) is typing.Union:
        args = [a for a in typing.get_args(annotation) if a is not type(None)]
        if len(args) == 1:
            return args[0]
    return annotation


def _default(info: FieldInfo) -> Any:
    """The model's default of a field (None for a required one)."""
    if info.default_factory is not None:
        return info.default_factory()  # type: ignore[call-arg]
    return None if info.is_required() else copy.deepcopy(info.default)


def _plain(value: Any) -> Any:
    """A value as a session stores it (lists, not tuples)."""
    if isinstance(value, (tuple, list)):
        return [_plain(v) for v in value]
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
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


def _number_box(annotation: Any, info: Optional[FieldInfo] = None) -> Union[QSpinBox, FloatBox]:
    """A spin box for an int or float with the field's bounds (the whole range where it has none) and unit."""
    if annotation is not int:
        return _float_box(info)
    lower, upper = field_bounds(info) if info is not None else (None, None)
    box = QSpinBox()
    box.setKeyboardTracking(False)
    box.setRange(int(lower) if lower is not None else -INT_LIMIT, int(upper) if upper is not None else INT_LIMIT)
    _show_unit(box, info)
    return box


def _float_box(info: Optional[FieldInfo] = None) -> FloatBox:
    """A spin box for a float with the field's bounds (the whole range where it has none) and unit."""
    lower, upper = field_bounds(info) if info is not None else (None, None)
    box = FloatBox()
    box.setRange(float(lower) if lower is not None else -FLOAT_LIMIT,
                 float(upper) if upper is not None else FLOAT_LIMIT)
    _show_unit(box, info)
    return box


def _show_unit(box: Union[QSpinBox, FloatBox], info: Optional[FieldInfo]) -> None:
    unit = _hints(info).get("unit") if info is not None else None
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


class _Editor(Generic[_W]):
    """The editor of one field: ``widget``, ``value()`` (as the session stores it) and ``show(value)`` (no report);
    ``edited`` is called when the user committed a value."""

    def __init__(self, widget: _W, edited: Callable[[], None]) -> None:
        self.widget, self.edited = widget, edited

    def value(self) -> Any:
        raise NotImplementedError

    def show(self, value: Any) -> None:
        raise NotImplementedError


class _CheckBox(_Editor[QCheckBox]):
    def __init__(self, edited: Callable[[], None]) -> None:
        super().__init__(QCheckBox(), edited)
        self.widget.toggled.connect(lambda _on: self.edited())

    def value(self) -> bool:
        return self.widget.isChecked()

    def show(self, value: Any) -> None:
        self.widget.blockSignals(True)
        self.widget.setChecked(bool(value))
        self.widget.blockSignals(False)


class _Choice(_Editor[QComboBox]):
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


class _Number(_Editor[Union[QSpinBox, FloatBox]]):
    def __init__(self, annotation: Any, info: FieldInfo, edited: Callable[[], None]) -> None:
        super().__init__(_number_box(annotation, info), edited)
        self.kind = annotation
        self.widget.editingFinished.connect(self.edited)

    def value(self) -> Any:
        return self.kind(self.widget.value())

    def show(self, value: Any) -> None:
        self.widget.blockSignals(True)
        self.widget.setValue(self.kind(self.widget.minimum()) if value is None else value)
        self.widget.blockSignals(False)


class _Vector(_Editor[QWidget]):
    """A row of spin boxes for a fixed-length tuple (extent, origin, grid shape)."""

    def __init__(self, kinds: Sequence[Any], info: FieldInfo, edited: Callable[[], None]) -> None:
        super().__init__(QWidget(), edited)
        row = QHBoxLayout(self.widget)
        row.setContentsMargins(0, 0, 0, 0)
        unit = _hints(info).get("unit")
        self.kinds = list(kinds)
        self.boxes: list[Union[QSpinBox, FloatBox]] = []
        for kind in self.kinds:
            box = _number_box(kind)
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


class _Color(_Editor[ColorButton]):
    def __init__(self, edited: Callable[[], None]) -> None:
        super().__init__(ColorButton(), edited)
        self.widget.chosen.connect(self.edited)

    def value(self) -> list[float]:
        return list(self.widget.rgb)

    def show(self, value: Any) -> None:
        self.widget.set_rgb(value if value is not None else (1.0, 1.0, 1.0))


class _ReadOnly(_Editor[QLabel]):
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
        value = _float_box(fields["value"])
        value.setValue(float(style.get("value", 0.0)))
        color = ColorButton()
        color.set_rgb(style.get("color", _default(fields["color"])))
        opacity = _float_box(fields["opacity"])
        opacity.setValue(float(style.get("opacity", _default(fields["opacity"]))))
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


class _Styles(_Editor[StylesTable]):
    def __init__(self, edited: Callable[[], None]) -> None:
        super().__init__(StylesTable(), edited)
        self.widget.edited.connect(self.edited)

    def value(self) -> list[dict[str, Any]]:
        return self.widget.styles()

    def show(self, value: Any) -> None:
        self.widget.set_styles(value or [])


class _Row:
    """One field of the form: its label (a check box "set" for a field with a default), editor and problem text."""

    def __init__(self, name: str, info: FieldInfo, editor: _Editor[QWidget]) -> None:
        self.name, self.info, self.editor = name, info, editor
        self.default = _default(info)
        title = info.title or name
        self.label: QWidget = QCheckBox(title) if not info.is_required() else QLabel(title)
        self.error = QLabel()
        self.error.setWordWrap(True)
        self.error.setStyleSheet("color: #c00000")
        self.error.hide()
        tip = info.description or title
        self.label.setToolTip(f"{tip}\nTicked: set in the session; unticked: the default"
                              if isinstance(self.label, QCheckBox) else tip)
        editor.widget.setToolTip(tip)
        self.shown: Any = None   # the editor's value when it was last shown or committed

    def show(self, settings: dict[str, Any]) -> None:
        """Show the field's value in ``settings`` (its default when unset); an editor already showing it is left
        alone (it may be the one whose signal is being handled)."""
        value = settings.get(self.name, self.default)
        if self.editor.value() != _plain(value):
            self.editor.show(value)
        self.shown = self.editor.value()
        self.tick(self.name in settings)

    def tick(self, on: bool) -> None:
        """Tick (or untick) the label of a field with a default, reporting nothing."""
        if isinstance(self.label, QCheckBox):
            self.label.blockSignals(True)
            self.label.setChecked(on)
            self.label.blockSignals(False)


class SettingsForm(QWidget):
    """The settings of one component of type ``component_type`` as a form built from its settings model.
    ``datasets`` are the ids offered for dataset fields, ``arrays()`` the names offered for array fields (asked only
    when the model has one: listing a dataset's arrays reads them all); fields named
    in ``skip`` get no row (their keys are kept as they are). ``settings`` is the dict the form stands for;
    ``committed(before, after)`` reports each accepted edit."""

    committed = Signal(dict, dict)

    def __init__(self, component_type: str, settings: dict[str, Any], datasets: Sequence[str] = (),
                 arrays: Callable[[], Sequence[str]] = tuple, skip: Sequence[str] = (),
                 parent: Optional[QWidget] = None) -> None:
        super().__init__(parent)
        self.component_type = component_type
        self.model = settings_model(component_type)
        self.settings: dict[str, Any] = copy.deepcopy(settings)
        self.rows: dict[str, _Row] = {}
        layout = QFormLayout(self)
        layout.setContentsMargins(0, 0, 0, 0)
        layout.setRowWrapPolicy(QFormLayout.RowWrapPolicy.WrapLongRows)  # a narrow dock: editors under their labels
        self.message = QLabel()  # problems that belong to no row
        self.message.setWordWrap(True)
        self.message.setStyleSheet("color: #c00000")
        self.message.hide()
        for name, info in self.model.model_fields.items():
            if name in skip:
                continue
            row = _Row(name, info, self._editor(name, info, datasets, arrays))
            cell = QWidget()
            column = QVBoxLayout(cell)
            column.setContentsMargins(0, 0, 0, 0)
            column.addWidget(row.editor.widget)
            column.addWidget(row.error)
            layout.addRow(row.label, cell)
            row.show(self.settings)
            if isinstance(row.label, QCheckBox):
                row.label.toggled.connect(lambda on, r=row: self._set_toggled(r, on))
            self.rows[name] = row
        if not self.rows:
            layout.addRow(QLabel("No settings"))
        layout.addRow(self.message)

    def _editor(self, name: str, info: FieldInfo, datasets: Sequence[str],
                arrays: Callable[[], Sequence[str]]) -> _Editor[QWidget]:
        edited = lambda: self._edited(name)  # noqa: E731
        hints, annotation = _hints(info), _without_none(info.annotation)
        origin = typing.get_origin(annotation)
        if hints.get("color"):
            return _Color(edited)
        if hints.get("dataset"):
            return _Choice(datasets, edited)
        if hints.get("array"):
            return _Choice(arrays(), edited)
        if annotation is bool:
            return _CheckBox(edited)
        if origin is Literal:
            return _Choice(typing.get_args(annotation), edited)
        if annotation in (int, float):
            return _Number(annotation, info, edited)
        if origin is tuple:
            return _Vector(typing.get_args(annotation), info, edited)
        if origin is list and typing.get_args(annotation) == (IsoStyleSettings,):
            return _Styles(edited)
        return _ReadOnly(CLIP_NOTE if name == "clip" else "not editable here")

    def editor(self, name: str) -> QWidget:
        """The editor widget of field ``name``."""
        return self.rows[name].editor.widget

    def problem(self, name: str) -> str:
        """The problem shown next to field ``name`` ("" when none)."""
        return self.rows[name].error.text()

    def _edited(self, name: str) -> None:
        row = self.rows[name]
        value = row.editor.value()
        if value != row.shown:
            self.commit({**self.settings, name: value})

    def _set_toggled(self, row: _Row, on: bool) -> None:
        settings = dict(self.settings)
        if on:
            settings[row.name] = row.editor.value()
        else:
            settings.pop(row.name, None)
        self.commit(settings)

    def commit(self, settings: dict[str, Any]) -> bool:
        """Take ``settings`` as the component's new settings if its model accepts them (then ``committed`` reports
        them); otherwise show each problem next to its field and change nothing."""
        settings = _plain(settings)
        try:
            typed_settings(self.component_type, settings)
        except SettingsError as exc:
            self._show_problems(exc.problems)
            for row in self.rows.values():
                row.tick(row.name in self.settings)
            return False
        self._show_problems([])
        before, self.settings = self.settings, settings
        for row in self.rows.values():
            row.show(settings)
        self.committed.emit(copy.deepcopy(before), copy.deepcopy(settings))
        return True

    def _show_problems(self, problems: list[tuple[str, str]]) -> None:
        by_row: dict[str, list[str]] = {}
        rest: list[str] = []
        for path, message in problems:
            field = path.removeprefix("settings").lstrip(".").split(".")[0].split("[")[0]
            (by_row.setdefault(field, []) if field in self.rows else rest).append(f"{path}: {message}")
        for name, row in self.rows.items():
            row.error.setText("\n".join(by_row.get(name, [])))
            row.error.setVisible(name in by_row)
        self.message.setText("\n".join(rest))
        self.message.setVisible(bool(rest))
