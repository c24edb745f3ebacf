"""Scene tree dock: the session's components with visibility check boxes, an opacity slider, the array shown and
the selected component's settings as a form (``volviz_app.settings_form``) of the fields that apply to its dataset
(``volviz.model.applicability``)."""
from __future__ import annotations

from typing import Any, Callable, Optional, Sequence

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (QComboBox, QGroupBox, QHBoxLayout, QLabel, QSlider, QTreeWidget, QTreeWidgetItem,
                               QVBoxLayout, QWidget)

from volviz.model.applicability import DatasetTraits, applicable_fields
from volviz.model.settings import settings_model
from ..settings_form import SettingsForm

KIND_LABELS = {"volume": "Volume", "mesh": "Mesh", "isosurface": "Isosurface", "terrain": "Terrain",
               "fog": "Ground fog", "clouds": "Clouds", "sky": "Sky", "demo": "Demo volume"}
DRAWN_AS_LABELS = {"surface": "Surface", "points": "Points"}


#: settings the form leaves to other editors: the array combo box (``volviz_app.array_choice``) and the Timeline
#: dock's Interpolate switch, one for the whole scene (``volviz.render.controller.session_interpolates``)
FORM_SKIPS = ("array", "interpolate")


class SceneTree(QWidget):
    """Components with visibility check boxes, an opacity slider, and the selected one's settings as a form built
    from its settings model; each edit the form accepts is reported by ``settingsEdited(id, before, after)``."""

    visibilityChanged = Signal(str, bool)
    opacityChanged = Signal(str, float)
    componentSelected = Signal(str)
    settingsEdited = Signal(str, dict, dict)  # component id, settings before, settings after
    populated = Signal()  # a (new) scene's components are listed

    def __init__(self, parent: Optional[QWidget] = None):
        super().__init__(parent)
        self.tree = QTreeWidget()
        self.tree.setHeaderLabels(["Component", "Kind"])
        self.tree.setRootIsDecorated(False)
        self.opacity = QSlider(Qt.Orientation.Horizontal)
        self.opacity.setRange(0, 100)
        self.opacity.setEnabled(False)
        self.opacity_label = QLabel("Opacity")
        row = QHBoxLayout()
        row.addWidget(self.opacity_label)
        row.addWidget(self.opacity, 1)
        self.array = QComboBox()  # filled by the window (``volviz_app.array_choice``)
        self.array_label = QLabel("Array")
        array_row = QHBoxLayout()
        array_row.addWidget(self.array_label)
        array_row.addWidget(self.array, 1)
        self.settings_box = QGroupBox("Settings")
        self.settings_layout = QVBoxLayout(self.settings_box)
        self.form: Optional[SettingsForm] = None
        self.tree.setToolTip("The scene's components: tick to show, untick to hide; select one to edit it")
        self.opacity.setToolTip("Opacity of the selected component")
        self.settings_box.setToolTip("The selected component's settings: a change applies at once (Edit > Undo "
                                     "takes it back)")
        layout = QVBoxLayout(self)
        layout.addWidget(self.tree, 1)
        layout.addLayout(array_row)
        layout.addLayout(row)
        layout.addWidget(self.settings_box)
        self.tree.itemChanged.connect(self._item_changed)
        self.tree.currentItemChanged.connect(self._current_changed)
        self.opacity.valueChanged.connect(self._opacity_moved)
        self._filling = False
        self._components: dict[str, Any] = {}
        self._datasets: Sequence[str] = ()
        self._arrays: Callable[[str], list[str]] = lambda comp_id: []
        self._traits: Callable[[str], Optional[DatasetTraits]] = lambda comp_id: None
        self._drawn_as: Callable[[str], Optional[str]] = lambda comp_id: None

    def populate(self, components: list[Any], datasets: Sequence[str] = (),
                 arrays: Optional[Callable[[str], list[str]]] = None,
                 traits: Optional[Callable[[str], Optional[DatasetTraits]]] = None,
                 drawn_as: Optional[Callable[[str], Optional[str]]] = None) -> None:
        """List ``components``; their forms offer ``datasets`` (ids) for dataset fields and ``arrays(component id)``
        for array fields, and show the fields that apply to ``traits(component id)`` (what its dataset is; None or
        no ``traits``: every field); ``drawn_as(component id)`` ("surface", "points") refines the Kind column. The
        selected component stays selected if it is still there (else the first is)."""
        selected = self.current_component()
        self._filling = True
        self.tree.clear()
        self._components = {comp.id: comp for comp in components}
        self._datasets = list(datasets)
        self._arrays = arrays or (lambda comp_id: [])
        self._traits = traits or (lambda comp_id: None)
        self._drawn_as = drawn_as or (lambda comp_id: None)
        for comp in components:
            item = QTreeWidgetItem([comp.id, self._kind_label(comp)])
            item.setData(0, Qt.ItemDataRole.UserRole, comp.id)
            item.setData(0, Qt.ItemDataRole.UserRole + 1, comp.opacity)
            item.setFlags(item.flags() | Qt.ItemFlag.ItemIsUserCheckable)
            item.setCheckState(0, Qt.CheckState.Checked if comp.visible else Qt.CheckState.Unchecked)
            self.tree.addTopLevelItem(item)
        self._filling = False
        first = self.tree.topLevelItem(0)  # None: no components
        if first is not None:
            self.tree.setCurrentItem(self.item(selected) if selected in self._components else first)
        else:
            self._show_form(None)
        self.populated.emit()

    def _kind_label(self, comp: Any) -> str:
        """The Kind column: the component's type, or how it draws its dataset where that says more (a surface, a
        set of points)."""
        return DRAWN_AS_LABELS.get(self._drawn_as(comp.id) or "", KIND_LABELS.get(comp.type, comp.type))

    def item(self, comp_id: str) -> QTreeWidgetItem:
        for i in range(self.tree.topLevelItemCount()):
            item = self.tree.topLevelItem(i)
            if item is not None and item.data(0, Qt.ItemDataRole.UserRole) == comp_id:
                return item
        raise KeyError(comp_id)

    def current_component(self) -> Optional[str]:
        item = self.tree.currentItem()
        return None if item is None else item.data(0, Qt.ItemDataRole.UserRole)

    def _item_changed(self, item: QTreeWidgetItem, column: int) -> None:
        if not self._filling and column == 0:
            self.visibilityChanged.emit(item.data(0, Qt.ItemDataRole.UserRole),
                                        item.checkState(0) == Qt.CheckState.Checked)

    def _current_changed(self, current: Optional[QTreeWidgetItem], previous: Any) -> None:
        self.opacity.setEnabled(current is not None)
        if current is None:
            return
        self._filling = True
        self.opacity.setValue(int(round(float(current.data(0, Qt.ItemDataRole.UserRole + 1)) * 100)))
        self._filling = False
        comp_id = current.data(0, Qt.ItemDataRole.UserRole)
        self._show_form(comp_id)
        self.componentSelected.emit(comp_id)

    def _show_form(self, comp_id: Optional[str]) -> None:
        """Swap in the settings form of ``comp_id`` (none for None): the fields that apply to its dataset, less
        ``FORM_SKIPS``; the values of the others stay in its settings."""
        if self.form is not None:
            self.settings_layout.removeWidget(self.form)
            self.form.setParent(None)  # gone from the dock now, deleted once its signal handlers returned
            self.form.deleteLater()
            self.form = None
        comp = self._components.get(comp_id) if comp_id is not None else None
        self.settings_box.setTitle(f"Settings of {comp_id}" if comp is not None else "Settings")
        if comp is None:
            return
        applicable = applicable_fields(comp.type, self._traits(comp.id))
        skip = [name for name in settings_model(comp.type).model_fields if name in FORM_SKIPS or name not in applicable]
        self.form = SettingsForm(comp.type, comp.settings, self._datasets, lambda: self._arrays(comp.id), skip)
        self.form.committed.connect(lambda before, after: self.settingsEdited.emit(comp.id, before, after))
        self.settings_layout.addWidget(self.form)

    def dataset_read(self, comp_id: str) -> None:
        """The dataset of ``comp_id`` was read (it was not when the form was made): its form, if shown, is made again
        when other fields now apply."""
        if self.form is None or self.current_component() != comp_id:
            return
        comp = self._components[comp_id]
        shown = [name for name in applicable_fields(comp.type, self._traits(comp_id)) if name not in FORM_SKIPS]
        if shown != list(self.form.rows):
            self._show_form(comp_id)

    def show_state(self, comp_id: str, visible: bool, opacity: float) -> None:
        """Show a component's visibility and opacity as the scene holds them (after a change made anywhere: the dock,
        an undo, a failed show), without emitting the dock's signals."""
        item = self.item(comp_id)
        self._filling = True
        try:
            item.setCheckState(0, Qt.CheckState.Checked if visible else Qt.CheckState.Unchecked)
            item.setData(0, Qt.ItemDataRole.UserRole + 1, float(opacity))
            if self.tree.currentItem() is item:
                self.opacity.setValue(int(round(float(opacity) * 100)))
        finally:
            self._filling = False

    def _opacity_moved(self, value: int) -> None:
        item = self.tree.currentItem()
        if self._filling or item is None:
            return
        item.setData(0, Qt.ItemDataRole.UserRole + 1, value / 100.0)
        self.opacityChanged.emit(item.data(0, Qt.ItemDataRole.UserRole), value / 100.0)
