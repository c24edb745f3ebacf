"""The scene tree's settings form, generated from each component type's settings model (issue #18): the widgets it
builds, edits that rebuild the scene and Edit > Undo that takes them back, fields set back to their default."""
from __future__ import annotations

import json
import typing
from pathlib import Path
from typing import Any, Literal

import numpy as np
import pytest
from PySide6.QtCore import Qt
from PySide6.QtWidgets import QCheckBox, QComboBox, QDoubleSpinBox, QLabel, QSpinBox

from test_app_workflows import viewport, wait_loaded
from volviz.model.settings import SETTINGS_MODELS
from volviz_app.settings_editors import ColorButton, StylesTable
from volviz_app.settings_form import SettingsForm

DATASETS = ["height_map", "fog_map"]
ARRAYS = ["density", "temperature"]


def _form(qtbot, kind: str, settings: dict[str, Any]) -> SettingsForm:
    form = SettingsForm(kind, settings, DATASETS, lambda: ARRAYS)
    qtbot.addWidget(form)
    return form


def _bare(annotation: Any) -> Any:
    args = [a for a in typing.get_args(annotation) if a is not type(None)]
    return args[0] if typing.get_origin(annotation) is typing.Union and len(args) == 1 else annotation


@pytest.mark.parametrize("kind", sorted(SETTINGS_MODELS))
def test_form_of_each_component_type_has_the_models_widgets(qtbot, kind: str) -> None:
    model = SETTINGS_MODELS[kind]
    form = _form(qtbot, kind, {})
    assert set(form.rows) == set(model.model_fields)
    for name, info in model.model_fields.items():
        widget, extra = form.editor(name), info.json_schema_extra or {}
        label = form.rows[name].label
        assert label.text() == (info.title or name) and label.toolTip().startswith(info.description or label.text())
        annotation = _bare(info.annotation)
        if extra.get("color"):
            assert isinstance(widget, ColorButton)
        elif extra.get("dataset") or extra.get("array"):
            names = DATASETS if extra.get("dataset") else ARRAYS
            assert isinstance(widget, QComboBox)
            assert [widget.itemText(i) for i in range(widget.count())] == names
        elif annotation is bool:
            assert isinstance(widget, QCheckBox)
        elif typing.get_origin(annotation) is Literal:
            assert isinstance(widget, QComboBox)
            assert [widget.itemText(i) for i in range(widget.count())] == list(typing.get_args(annotation))
        elif annotation in (int, float):
            assert isinstance(widget, QSpinBox if annotation is int else QDoubleSpinBox)
            for bound in info.metadata:
                lower = next((getattr(bound, k) for k in ("ge", "gt") if getattr(bound, k, None) is not None), None)
                if lower is not None:
                    assert widget.minimum() == lower
                if getattr(bound, "le", None) is not None:
                    assert widget.maximum() == bound.le
            assert widget.suffix() == (f" {extra['unit']}" if "unit" in extra else "")
        elif typing.get_origin(annotation) is tuple:
            boxes = widget.findChildren(QSpinBox if typing.get_args(annotation)[0] is int else QDoubleSpinBox)
            assert len(boxes) == len(typing.get_args(annotation))
        elif name == "styles":
            assert isinstance(widget, StylesTable) and widget.table.columnCount() == 3
        else:
            assert name == "clip" and isinstance(widget, QLabel) and "Clipping dock" in widget.text()


def test_form_widgets_of_fog_and_isosurface(qtbot) -> None:
    fog = _form(qtbot, "fog", {"density": 0.04})
    mode = fog.editor("mode")
    assert [mode.itemText(i) for i in range(mode.count())] == ["emissive", "attenuated", "mip"]
    assert mode.currentText() == "attenuated"                        # the model's default
    density = fog.editor("density")
    assert (density.minimum(), density.maximum(), density.suffix()) == (0.0, 1000.0, " 1/m")
    assert density.value() == pytest.approx(0.04) and fog.rows["density"].label.isChecked()
    assert not fog.rows["mode"].label.isChecked()                    # not set: the default
    iso = _form(qtbot, "isosurface", {"styles": [{"value": 3.0}, {"value": 5.0, "opacity": 0.1}]})
    table = iso.editor("styles").table
    assert table.rowCount() == 2
    assert (table.cellWidget(1, 0).value(), table.cellWidget(1, 2).value()) == (5.0, pytest.approx(0.1))
    assert table.cellWidget(0, 1).rgb == (1.0, 1.0, 1.0) and table.cellWidget(0, 2).value() == 0.5  # defaults
    assert table.cellWidget(0, 2).maximum() == 1.0


def test_form_commits_validated_settings(qtbot) -> None:
    form = _form(qtbot, "isosurface", {"styles": [{"value": 3.0}]})
    commits: list[tuple[dict, dict]] = []
    form.committed.connect(lambda before, after: commits.append((before, after)))
    styles = form.editor("styles")
    styles.add_button.click()                                        # a copy of the last surface
    assert commits[-1][1]["styles"] == [{"value": 3.0, "color": [1.0, 1.0, 1.0], "opacity": 0.5}] * 2
    styles.table.cellWidget(1, 2).setValue(0.25)
    styles.table.cellWidget(1, 2).editingFinished.emit()
    assert form.settings["styles"][1]["opacity"] == 0.25
    styles.table.selectRow(0)
    styles.remove_button.click()
    assert form.settings["styles"] == [{"value": 3.0, "color": [1.0, 1.0, 1.0], "opacity": 0.25}]
    form.editor("shading").setCurrentText("flat")
    assert commits[-1][1]["shading"] == "flat" and len(commits) == 4
    kept = dict(form.settings)
    assert not form.commit({**kept, "mode": "5pass"})                # refused: the field's message, nothing changes
    assert "settings.mode" in form.problem("mode") and "5pass" in form.problem("mode")
    assert form.settings == kept and len(commits) == 4


def test_optional_field_set_back_to_default_leaves_the_settings(qtbot) -> None:
    form = _form(qtbot, "clouds", {"thickness": 30.0, "seed": 4})
    commits: list[dict] = []
    form.committed.connect(lambda before, after: commits.append(after))
    thickness = form.rows["thickness"]
    assert thickness.label.isChecked() and form.editor("thickness").value() == 30.0
    thickness.label.setChecked(False)                                # back to the default (the grid's aspect)
    assert commits[-1] == {"seed": 4} and form.settings == {"seed": 4}
    form.rows["seed"].label.setChecked(False)
    assert commits[-1] == {} and form.editor("seed").value() == 3   # the model's default shown
    form.editor("thickness").setValue(12.5)
    form.editor("thickness").editingFinished.emit()                  # a value entered sets the field again
    assert commits[-1] == {"thickness": 12.5} and thickness.label.isChecked()


def _select(window, comp_id: str) -> SettingsForm:
    tree = window.scene_tree
    tree.tree.setCurrentItem(tree.item(comp_id))
    assert tree.form is not None and tree.settings_box.title().endswith(comp_id)
    return tree.form


def _settings(window, comp_id: str) -> dict[str, Any]:
    return next(c for c in window.session.components if c.id == comp_id).settings


def test_fog_density_edited_in_the_form_and_undone(qtbot, make_window) -> None:
    window = make_window()
    window.open_demo()
    wait_loaded(qtbot, window)
    density = _select(window, "ground_fog").editor("density")
    assert density.value() == pytest.approx(0.04)
    before = viewport(window)
    density.lineEdit().selectAll()
    qtbot.keyClicks(density.lineEdit(), "0.4")                      # ten times denser fog
    qtbot.keyClick(density.lineEdit(), Qt.Key.Key_Return)
    wait_loaded(qtbot, window)                                       # rebuilt in the background
    assert _settings(window, "ground_fog")["density"] == pytest.approx(0.4) and window.dirty
    denser = viewport(window)
    changed = np.abs(denser - before).sum(axis=2)
    assert (changed > 30).mean() > 0.01
    assert window.scene_tree.current_component() == "ground_fog"    # the selection stays
    assert window.scene_tree.form.editor("density").value() == pytest.approx(0.4)

    window.action_undo.trigger()                                     # Edit > Undo: the previous density, rebuilt
    wait_loaded(qtbot, window)
    assert _settings(window, "ground_fog")["density"] == pytest.approx(0.04)
    assert window.scene_tree.form.editor("density").value() == pytest.approx(0.04)
    assert np.abs(viewport(window) - before).sum(axis=2).mean() < 0.05 * changed.mean()
    window.action_redo.trigger()
    wait_loaded(qtbot, window)
    assert _settings(window, "ground_fog")["density"] == pytest.approx(0.4)


def test_optional_setting_set_back_to_default_in_the_scene(qtbot, make_window) -> None:
    window = make_window()
    window.open_demo()
    wait_loaded(qtbot, window)
    assert _settings(window, "terrain")["extent"] == [1000.0, 1000.0]
    _select(window, "terrain").rows["extent"].label.setChecked(False)  # the default extent (1000 x 1000)
    wait_loaded(qtbot, window)
    assert "extent" not in _settings(window, "terrain") and window.dirty
    assert not _select(window, "terrain").rows["extent"].label.isChecked()
    window.action_undo.trigger()
    wait_loaded(qtbot, window)
    assert _settings(window, "terrain")["extent"] == [1000.0, 1000.0]


def test_opening_another_scene_forgets_the_settings_edits_of_the_old_one(qtbot, make_window) -> None:
    """An Undo after opening another scene must not apply the old scene's settings to a component of the same id."""
    window = make_window()
    window.open_demo()
    wait_loaded(qtbot, window)
    _select(window, "ground_fog")  # the fog's form is shown
    density = window.scene_tree.form.editor("density")
    density.lineEdit().selectAll()
    qtbot.keyClicks(density.lineEdit(), "0.2")
    qtbot.keyClick(density.lineEdit(), Qt.Key.Key_Return)
    wait_loaded(qtbot, window)
    assert window.scene_undo_stack.canUndo()
    window.dirty = False
    window.open_demo()                                                # the same ids, a new scene
    wait_loaded(qtbot, window)
    assert not window.scene_undo_stack.canUndo()
    assert _settings(window, "ground_fog")["density"] == pytest.approx(0.04)


def _row_labels(form: SettingsForm) -> list[str]:
    """The texts of the form's row labels, as the dock shows them (an on/off setting's row is its titled box)."""
    from PySide6.QtWidgets import QFormLayout

    layout = form.layout()
    texts = []
    for i in range(layout.rowCount()):
        label = layout.itemAt(i, QFormLayout.ItemRole.LabelRole)
        whole = layout.itemAt(i, QFormLayout.ItemRole.SpanningRole)
        if label is not None and label.widget() is not None:
            texts.append(label.widget().text())
        elif whole is not None and whole.widget() is not None:
            texts += [box.text() for box in whole.widget().findChildren(QCheckBox) if box.text()]
    return texts


def test_form_shows_only_the_settings_that_apply_to_the_dataset(qtbot, make_window, tmp_path: Path) -> None:
    """A tetrahedral volume has no block budget; a compressed volume drawn at a level of detail has one; a time
    series' interpolation is the Timeline dock's switch for the whole scene, not a row of the form. A setting the session gives that does not
    apply stays in its settings through edits of the others. A component hidden at load (its dataset not read) shows
    every field until it is shown."""
    from conftest import blob_vvz
    from test_app_background import write_pvm_series
    from volviz.model.demo import demo_tet_mesh

    demo_tet_mesh(4).to_pyvista().save(tmp_path / "tets.vtu")
    demo_tet_mesh(3).to_pyvista().save(tmp_path / "later.vtu")
    write_pvm_series(tmp_path, 3, 16)
    blob_vvz(tmp_path / "blob.vvz", 32)
    session_file = tmp_path / "applies.json"
    session_file.write_text(json.dumps({
        "format": "volviz-session", "version": 1,
        "datasets": [{"id": "tets", "path": str(tmp_path / "tets.vtu")},
                     {"id": "series", "path": str(tmp_path / "blob.pvm-t%02d")},
                     {"id": "blob", "path": str(tmp_path / "blob.vvz"), "options": {"lod": True}},
                     {"id": "later", "path": str(tmp_path / "later.vtu")}],
        "components": [
            {"id": "tets", "type": "volume", "dataset": "tets", "settings": {"budget": 64}},
            {"id": "series", "type": "volume", "dataset": "series"},
            {"id": "blob", "type": "volume", "dataset": "blob", "settings": {"budget": 16}},
            {"id": "iso", "type": "isosurface", "dataset": "tets",
             "settings": {"styles": [{"value": 0.3, "opacity": 0.5}], "interpolate": False}},
            {"id": "later", "type": "volume", "dataset": "later", "visible": False}]}))
    window = make_window()
    window.open_path(session_file)
    wait_loaded(qtbot, window)
    assert window.error_dialog is None

    tets = _select(window, "tets")
    assert "Block budget" not in _row_labels(tets) and "Interpolate in time" not in _row_labels(tets)
    # budget not shown, still set
    assert set(tets.rows) == {"log_scale", "shade"} and tets.settings == {"budget": 64}
    series = _select(window, "series")       # its interpolation is the Timeline dock's switch, not a form row
    assert "Interpolate in time" not in _row_labels(series) and "Block budget" not in _row_labels(series)
    assert list(series.rows) == ["log_scale", "shade"]
    blob = _select(window, "blob")
    assert "Block budget" in _row_labels(blob) and "Interpolate in time" not in _row_labels(blob)
    assert list(blob.rows) == ["budget", "log_scale", "shade"] and blob.editor("budget").value() == 16
    iso = _select(window, "iso")
    assert "Interpolate in time" not in _row_labels(iso)
    assert {"Transparency mode", "Level of detail", "Triangles per pixel²"} <= set(_row_labels(iso))

    iso.editor("shading").setCurrentText("flat")                      # an edit of a shown field
    wait_loaded(qtbot, window)
    assert _settings(window, "iso")["shading"] == "flat"
    assert _settings(window, "iso")["interpolate"] is False             # the hidden one kept
    assert "Interpolate in time" not in _row_labels(_select(window, "iso"))
    assert _settings(window, "tets") == {"budget": 64}

    assert list(_select(window, "later").rows) == ["budget", "log_scale", "shade"]   # not read: not known
    shown = window.components_shown
    window.scene_tree.item("later").setCheckState(0, Qt.CheckState.Checked)
    qtbot.waitUntil(lambda: window.components_shown > shown, timeout=60000)
    assert window.scene_tree.current_component() == "later"
    assert list(window.scene_tree.form.rows) == ["log_scale", "shade"]
    assert "Block budget" not in _row_labels(window.scene_tree.form)
