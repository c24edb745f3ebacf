"""Statistics dock: frame time split, cells drawn, the current method's measured error estimate, the OpenGL renderer
and the backend that draws each PT volume (``volviz.render.backend``)."""
from __future__ import annotations

from typing import Any, Optional

from PySide6.QtWidgets import QFormLayout, QLabel, QWidget


TIPS = {"frame": "Time to draw the last frame, and the frame rate it allows",
        "split": "Where volviz's renderer spent the last frame: visibility sort, projection, rasterisation",
        "cells": "Cells of the datasets shown",
        "method": "The renderer and table that drew the last frame",
        "error": "Error of the current view measured against the exact reference (8-bit units)",
        "iso": "The isosurfaces' transparency mode, triangles and drawing time",
        "gl": "The OpenGL renderer of the viewport (a software rasteriser such as llvmpipe runs on the CPU)",
        "backends": "Where each PT volume is drawn: gpu (VTK's OpenGL with volviz's shaders) or cpu (volviz's "
                    "renderer, an image over the scene); the render setting Backend chooses"}


class Statistics(QWidget):
    FIELDS = (("frame", "Frame time"), ("split", "Sort / project / raster"), ("cells", "Cells drawn"),
              ("method", "Method"), ("error", "Error estimate"), ("iso", "Isosurfaces"), ("gl", "OpenGL"),
              ("backends", "PT backend"))

    def __init__(self, parent: Optional[QWidget] = None):
        super().__init__(parent)
        form = QFormLayout(self)
        self.labels: dict[str, QLabel] = {}
        for key, title in self.FIELDS:
            self.labels[key] = QLabel("–")
            self.labels[key].setToolTip(TIPS[key])
            form.addRow(title, self.labels[key])

    def show_stats(self, stats: dict[str, Any]) -> None:
        frame = stats.get("frame_seconds")
        self.labels["frame"].setText("–" if frame is None
                                     else f"{frame * 1000:.1f} ms ({1.0 / max(frame, 1e-9):.1f} fps)")
        split = [stats.get(k) for k in ("sort_seconds", "project_seconds", "raster_seconds")]
        self.labels["split"].setText(" / ".join("–" if v is None else f"{v * 1000:.1f} ms" for v in split))
        cells = stats.get("cells")
        self.labels["cells"].setText("–" if cells is None else f"{cells:,}")
        self.labels["method"].setText(str(stats.get("method", "–")))
        error = stats.get("error")
        self.labels["error"].setText("–" if error is None else str(error))
        self.labels["iso"].setText(str(stats.get("iso", "–")))
        self.labels["gl"].setText(str(stats.get("gl", "–")))
        backends = stats.get("backends")
        self.labels["backends"].setText(", ".join(f"{k}: {v}" for k, v in backends.items()) if backends else "–")

    def text(self, key: str) -> str:
        return self.labels[key].text()
