"""Scene tree dock: the session's components with visibility check boxes and an opacity slider."""
from __future__ import annotations

import json
from typing import Any, Optional

from PySide6.QtCore import Qt, Signal
from PySide6.QtWidgets import (QComboBox, QHBoxLayout, QLabel, QPlainTextEdit, QPushButton, QSlider, QTreeWidget,
                               QTreeWidgetItem, QVBoxLayout, QWidget)

KIND_LABELS = {"volume": "Volume", "mesh": "Mesh", "isosurface": "Isosurface", "terrain": "Terrain", "fog": "Ground fog",
               "clouds": "Clouds", "sky": "Sky", "demo": "Demo volume"}


class SceneTree(QWidget):
    """Components with visibility check boxes, an opacity slider and their settings as editable JSON (validated by
    the window through the session schema before anything changes)."""

    visibilityChanged = Signal(str, bool)
    opacityChanged = Signal(str, float)
    componentSelected = Signal(str)
    settingsEdited = Signal(str, str)  # component id, JSON text

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
        self.settings_edit = QPlainTextEdit()
        self.settings_edit.setPlaceholderText("component settings (JSON)")
        self.settings_edit.setMaximumHeight(140)
        self.apply_button = QPushButton("Apply settings")
        self.apply_button.clicked.connect(self._apply_settings)
        self.tree.setToolTip("The scene's components: tick to show, untick to hide; select one to edit it")
        self.opacity.setToolTip("Opacity of the selected component")
        self.settings_edit.setToolTip("The selected component's settings as JSON (see the README for the keys)")
        self.apply_button.setToolTip("Check the settings above and rebuild the component with them")
        layout = QVBoxLayout(self)
        layout.addWidget(self.tree, 1)
        layout.addLayout(array_row)
        layout.addLayout(row)
        layout.addWidget(self.settings_edit)
        layout.addWidget(self.apply_button)
        self.tree.itemChanged.connect(self._item_changed)
        self.tree.currentItemChanged.connect(self._current_changed)
        self.opacity.valueChanged.connect(self._opacity_moved)
        self._filling = False

    def populate(self, components: list[Any]) -> None:
        self._filling = True
        self.tree.clear()
        for comp in components:
            item = QTreeWidgetItem([comp.id, KIND_LABELS.get(comp.type, comp.type)])
            item.setData(0, Qt.ItemDataRole.UserRole, comp.id)
            item.setData(0, Qt.ItemDataRole.UserRole + 1, comp.opacity)
            item.setData(0, Qt.ItemDataRole.UserRole + 2, json.dumps(comp.settings, indent=1))
            item.setFlags(item.flags() | Qt.ItemFlag.ItemIsUserCheckable)
            item.setCheckState(0, Qt.CheckState.Checked if comp.visible else Qt.CheckState.Unchecked)
            self.tree.addTopLevelItem(item)
        self._filling = False
        if self.tree.topLevelItemCount():
            self.tree.setCurrentItem(self.tree.topLevelItem(0))

    def item(self, comp_id: str) -> QTreeWidgetItem:
        for i in range(self.tree.topLevelItemCount()):
            item = self.tree.topLevelItem(i)
            if item.data(0, Qt.ItemDataRole.UserRole) == comp_id:
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
        self.settings_edit.setPlainText(current.data(0, Qt.ItemDataRole.UserRole + 2) or "{}")
        self._filling = False
        self.componentSelected.emit(current.data(0, Qt.ItemDataRole.UserRole))

    def _apply_settings(self) -> None:
        comp_id = self.current_component()
        if comp_id is not None:
            self.settingsEdited.emit(comp_id, self.settings_edit.toPlainText())

    def _opacity_moved(self, value: int) -> None:
        item = self.tree.currentItem()
        if self._filling or item is None:
            return
        item.setData(0, Qt.ItemDataRole.UserRole + 1, value / 100.0)
        self.opacityChanged.emit(item.data(0, Qt.ItemDataRole.UserRole), value / 100.0)
