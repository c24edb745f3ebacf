"""Render settings dock: renderer method, backend (GPU or CPU, ``volviz.render.backend``; the GPU's PT volumes in a
thread of their own or in the scene's window, ``backend.gpu_in_thread``), pre-integration table kind
and resolution, sort mode, error budget, export image size. The table and sort settings apply to volviz's PT renderer
("auto" picks the table by each cell's optical depth); the error budget is checked against the measured error of the
current view (see MainWindow.estimate_error)."""
from __future__ import annotations

from typing import Any, Optional

from PySide6.QtCore import Signal
from PySide6.QtWidgets import QComboBox, QDoubleSpinBox, QFormLayout, QSpinBox, QWidget

from volviz.render.controller import ISO_MODES
from volviz.session import RENDER_BACKENDS

METHODS = ("auto", "pt", "reference", "vtk")
TABLE_KINDS = ("auto", "3d", "separable-1", "separable-2", "separable-4")
SORTS = ("mpvo", "centroid", "power")
RENDERER_DEFAULTS = {"sort": "mpvo", "table": "auto", "table_resolution": 128,   # what the widgets start with
                     "backend": "auto", "gpu_thread": "auto"}
GPU_THREAD = ("auto", "on", "off")


class RenderSettingsDock(QWidget):
    """Edits ``session.render``; emits ``changed(dict)`` with the new settings."""

    changed = Signal(dict)

    def __init__(self, parent: Optional[QWidget] = None):
        super().__init__(parent)
        self.method = QComboBox()
        self.method.addItems(METHODS)
        self.backend = QComboBox()
        self.backend.addItems(RENDER_BACKENDS)
        self.backend.setToolTip("Where volumes, isosurfaces and the natural scene are drawn: gpu (VTK's OpenGL with "
                                "volviz's shaders), cpu (volviz's renderers, VTK's CPU ray caster), or auto: the GPU "
                                "on a hardware OpenGL, the path measured faster on a software one such as llvmpipe")
        self.gpu_thread = QComboBox()
        self.gpu_thread.addItems(GPU_THREAD)
        self.gpu_thread.setToolTip("Where the GPU backend draws PT volumes: on, in a window of a thread of their own "
                                   "(shown as an image, the window never waits for them); off, in the scene's "
                                   "window; auto: in a thread on a software OpenGL such as llvmpipe, whose raster "
                                   "runs on the CPU")
        self.table_kind = QComboBox()
        self.table_kind.addItems(TABLE_KINDS)
        self.table_resolution = QComboBox()
        self.table_resolution.addItems(["64", "128", "256", "512"])
        self.table_resolution.setCurrentText("128")
        self.sort = QComboBox()
        self.sort.addItems(SORTS)
        self.sort.setCurrentText("mpvo")
        self.error_budget = QDoubleSpinBox()
        self.error_budget.setRange(0.0, 64.0)
        self.error_budget.setSingleStep(0.25)
        self.error_budget.setValue(1.0)
        self.error_budget.setSuffix(" /255 RMSE")
        self.error_budget.setToolTip("When the measured error of volviz's renderer exceeds this, the app switches to "
                                     "the most accurate pre-integration table")
        self.iso_mode = QComboBox()
        self.iso_mode.addItems(ISO_MODES)
        self.iso_mode.setToolTip("Transparency of isosurfaces: VTK's 2-pass blend, or volviz's modes (2-pass, "
                                 "order-independent 3-pass and 4-pass, exact sorted fragments) on the Backend's "
                                 "renderer: gpu (VTK's OpenGL) or cpu (volviz's compositor)")
        self.width_box = QSpinBox()
        self.height_box = QSpinBox()
        for box in (self.width_box, self.height_box):
            box.setRange(16, 16384)
        self.width_box.setValue(1024)
        self.height_box.setValue(768)
        self.method.setToolTip("Renderer: auto (volviz's PT for meshes, VTK for grids), pt (volviz's pre-integrated "
                               "projected tetrahedra), reference (exact ray integration, slow), vtk (VTK's mappers)")
        self.table_kind.setToolTip("Pre-integration table of volviz's renderer: a 3D table, or separable polynomial "
                                   "tables of degree 1, 2 or 4; auto picks per cell by its optical depth")
        self.table_resolution.setToolTip("Entries per axis of the pre-integration table (finer: more accurate, "
                                         "slower to build)")
        self.sort.setToolTip("Visibility sort of the cells: MPVO (exact for convex meshes), centroid distance, or "
                             "power distance")
        self.width_box.setToolTip("Width in pixels of exported screenshots and movies")
        self.height_box.setToolTip("Height in pixels of exported movies (screenshots keep the viewport's aspect "
                                   "ratio)")
        form = QFormLayout(self)
        form.addRow("Renderer", self.method)
        form.addRow("Backend", self.backend)
        form.addRow("GPU in a thread", self.gpu_thread)
        form.addRow("Table", self.table_kind)
        form.addRow("Table resolution", self.table_resolution)
        form.addRow("Sort", self.sort)
        form.addRow("Error budget", self.error_budget)
        form.addRow("Isosurfaces", self.iso_mode)
        form.addRow("Export width", self.width_box)
        form.addRow("Export height", self.height_box)
        for combo in (self.method, self.backend, self.gpu_thread, self.table_kind, self.table_resolution, self.sort,
                      self.iso_mode):
            combo.currentTextChanged.connect(self._emit)
        for spin_box in (self.error_budget, self.width_box, self.height_box):
            spin_box.valueChanged.connect(self._emit)
        self._loading = False

    def settings(self) -> dict[str, Any]:
        return {"method": self.method.currentText(), "size": (self.width_box.value(), self.height_box.value()),
                "options": {"backend": self.backend.currentText(), "gpu_thread": self.gpu_thread.currentText(),
                            "table": self.table_kind.currentText(),
                            "table_resolution": int(self.table_resolution.currentText()),
                            "sort": self.sort.currentText(), "error_budget": self.error_budget.value(),
                            "iso_mode": self.iso_mode.currentText()}}

    def load(self, render: Any) -> None:
        self._loading = True
        self.method.setCurrentText(render.method)
        self.width_box.setValue(render.size[0])
        self.height_box.setValue(render.size[1])
        opts = render.options
        self.backend.setCurrentText(str(opts.get("backend", "auto")))
        self.gpu_thread.setCurrentText(str(opts.get("gpu_thread", "auto")))
        self.table_kind.setCurrentText(str(opts.get("table", "auto")))
        self.table_resolution.setCurrentText(str(opts.get("table_resolution", 128)))
        self.sort.setCurrentText(str(opts.get("sort", "mpvo")))
        self.error_budget.setValue(float(opts.get("error_budget", 1.0)))
        self.iso_mode.setCurrentText(str(opts.get("iso_mode", "vtk")))
        self._loading = False

    def load_values(self, values: dict[str, Any]) -> None:
        """Show ``values`` (the shape ``settings`` returns) without emitting ``changed``."""
        from types import SimpleNamespace

        self.load(SimpleNamespace(method=values["method"], size=values["size"], options=values["options"]))

    def _emit(self, *args: Any) -> None:
        if not self._loading:
            self.changed.emit(self.settings())
