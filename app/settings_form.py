"""A component's settings as a form generated from its typed settings model (``volviz.model.settings``).

One row per field of the model: its title as the label, its description as the tooltip, and an editor chosen by the
field's type: a check box (bool), a combo box of the choices (``Literal``), a spin box with the field's bounds and
unit (int, float), a row of spin boxes (fixed-length tuples), a color button (``{"color": True}``), a combo box of
the session's datasets (``{"dataset": True}``) or of the dataset's arrays (``{"array": True}``), a table of surfaces
(the isosurfaces' ``styles``); a nested object without a model (the isosurfaces' clipping) is shown read-only.

A field the session sets has its label ticked; unticking it removes the key, so the model's default applies again
(sessions store only the settings that were set). A bool field is one check box with its title, ticked when on (issue
#28: a label box "set" beside an untitled value box read as the switch, and a click on "Log color scale" stored
false and changed nothing). Every committed edit (a spin box's editing finished, a combo box's
or check box's change, a color chosen) is checked with ``typed_settings`` first: a refused value shows the problem
next to its field and changes nothing; an accepted one is emitted as the whole new settings dict (``committed``).
"""
from __future__ import annotations

import copy
from typing import Any, Callable, Optional, Sequence

from pydantic.fields import FieldInfo
from PySide6.QtCore import Signal
from PySide6.QtWidgets import QCheckBox, QFormLayout, QLabel, QVBoxLayout, QWidget

from volviz.model.settings import SettingsError, settings_model, typed_settings

from .settings_editors import CheckBoxEditor, Editor, editor_for, field_default, plain

__all__ = ["SettingsForm"]


class _Row:
    """One field of the form: its label (a check box "set" for a field with a default), editor and problem text."""

    def __init__(self, name: str, info: FieldInfo, editor: Editor[QWidget]) -> None:
        self.name, self.info, self.editor = name, info, editor
        self.default = field_default(info)
        title = info.title or name
        self.switch = isinstance(editor, CheckBoxEditor)   # a bool: its box is the label, and the value
        if isinstance(editor, CheckBoxEditor):
            editor.widget.setText(title)
        self.label: QWidget = (editor.widget if self.switch else QCheckBox(title) if not info.is_required()
                               else QLabel(title))
        self.error = QLabel()
        self.error.setWordWrap(True)
        self.error.setStyleSheet("color: #c00000")
        self.error.hide()
        tip = info.description or title
        editor.widget.setToolTip(tip)
        if isinstance(self.label, QCheckBox) and not self.switch:
            self.label.setToolTip(f"{tip}\nTicked: set in the session; unticked: the default")
        self.shown: Any = None   # the editor's value when it was last shown or committed

    def show(self, settings: dict[str, Any]) -> None:
        """Show the field's value in ``settings`` (its default when unset); an editor already showing it is left
        alone (it may be the one whose signal is being handled)."""
        value = settings.get(self.name, self.default)
        if self.editor.value() != plain(value):
            self.editor.show(value)
        self.shown = self.editor.value()
        self.tick(self.name in settings)

    def tick(self, on: bool) -> None:
        """Tick (or untick) the label of a field with a default, reporting nothing (a bool's box shows its value)."""
        if isinstance(self.label, QCheckBox) and not self.switch:
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
            if row.switch:
                layout.addRow(cell)      # the box with its title, the whole row
            else:
                layout.addRow(row.label, cell)
            row.show(self.settings)
            if isinstance(row.label, QCheckBox) and not row.switch:
                row.label.toggled.connect(lambda on, r=row: self._set_toggled(r, on))
            self.rows[name] = row
        if not self.rows:
            layout.addRow(QLabel("No settings"))
        layout.addRow(self.message)

    def _editor(self, name: str, info: FieldInfo, datasets: Sequence[str],
                arrays: Callable[[], Sequence[str]]) -> Editor[QWidget]:
        return editor_for(name, info, datasets, arrays, lambda: self._edited(name))

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
        settings = plain(settings)
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
