"""The transfer-function editor's canvas: the data histogram, the extinction curve with its control points and the
color bar, drawn with QPainter; a click adds a point, a drag moves it, a right-click removes it, a double-click asks
for its color. Where a point goes is ``volviz.optics.tf_points``; with ``log_floor`` set the scalar axis is in log10
(``volviz.optics.log_scale``). The editor (``tf_editor``) turns the canvas's edits into transfer functions.
"""
from __future__ import annotations

from typing import Optional

import numpy as np
from PySide6.QtCore import QPointF, QRectF, Qt, Signal
from PySide6.QtGui import QColor, QImage, QMouseEvent, QPainter, QPainterPath, QPaintEvent, QPen
from PySide6.QtWidgets import QSizePolicy, QWidget

from volviz.optics.log_scale import axis_fraction, axis_value, log_ticks
from volviz.optics.tf_points import MIN_POINTS, insert_point, moved_scalar, remove_point

GESTURES = ("Click: add a point · drag a point: move it · right-click: remove it · double-click: "
            "change its color")
POINT_RADIUS = 5.0
MARGIN = 8.0
COLOR_BAR_HEIGHT = 18.0
MIN_HEIGHT = 110          # the canvas's least height, pixels: the dock then fits its column without scrolling at
#                           1280x740 and 1024x572 (issue #28: at 160 it scrolled and cut its last hint line)


class TransferFunctionCanvas(QWidget):
    """Draws histogram, extinction curve and color bar; lets the user drag, add and remove control points."""

    pointsEdited = Signal()      # while dragging
    editFinished = Signal(str)   # description of a finished edit
    colorRequested = Signal(int)

    def __init__(self, parent: Optional[QWidget] = None):
        super().__init__(parent)
        self.setMinimumSize(260, MIN_HEIGHT)
        self.setSizePolicy(QSizePolicy.Policy.Expanding, QSizePolicy.Policy.Expanding)
        self.setMouseTracking(True)
        self.scalars = np.array([0.0, 1.0])
        self.colors = np.ones((2, 3))
        self.extinction = np.array([0.0, 1.0])
        self.rho_view = 1.0
        self.histogram: Optional[np.ndarray] = None
        self.histogram_edges: Optional[np.ndarray] = None
        self.log_histogram = False
        self.log_floor: Optional[float] = None    # the scalar axis in log10 from this value (None: linear)
        self.histogram_pending = False  # computed in the background: a placeholder is drawn meanwhile
        self.selected: Optional[int] = None
        self._dragging = False

    # -- geometry ---------------------------------------------------------------------------------------------------
    def _plot_rect(self) -> QRectF:
        return QRectF(MARGIN, MARGIN, self.width() - 2 * MARGIN, self.height() - 3 * MARGIN - COLOR_BAR_HEIGHT)

    def _view_range(self) -> tuple[float, float]:
        lo, hi = float(self.scalars[0]), float(self.scalars[-1])
        if self.histogram_edges is not None:
            lo, hi = min(lo, float(self.histogram_edges[0])), max(hi, float(self.histogram_edges[-1]))
        return (lo, hi if hi > lo else lo + 1.0)

    def x_of(self, s: np.ndarray | float) -> np.ndarray:
        """The x pixel of scalar(s) ``s`` (the axis linear, or in log10 with ``log_floor``)."""
        r = self._plot_rect()
        return r.left() + axis_fraction(s, *self._view_range(), self.log_floor) * r.width()

    def to_screen(self, s: float, rho: float) -> QPointF:
        r = self._plot_rect()
        y = r.bottom() - min(rho / self.rho_view, 1.0) * r.height()
        return QPointF(float(self.x_of(s)), y)

    def from_screen(self, point: QPointF) -> tuple[float, float]:
        r = self._plot_rect()
        lo, hi = self._view_range()
        s = float(axis_value((point.x() - r.left()) / max(r.width(), 1.0), lo, hi, self.log_floor))
        rho = (r.bottom() - point.y()) / max(r.height(), 1.0) * self.rho_view
        return (float(np.clip(s, lo, hi)), float(np.clip(rho, 0.0, self.rho_view)))

    def point_at(self, pos: QPointF) -> Optional[int]:
        """The control point nearest ``pos`` within reach of a click, or None: the nearest, not the first in reach,
        so that a click on a point of a dense function (a 33-point preset in a short canvas) takes that point and not
        its neighbour."""
        nearest, reach = None, 2.5 * POINT_RADIUS
        for i in range(len(self.scalars)):
            distance = (self.to_screen(self.scalars[i], self.extinction[i]) - pos).manhattanLength()
            if distance <= reach:
                nearest, reach = i, distance
        return nearest

    # -- painting ---------------------------------------------------------------------------------------------------
    def paintEvent(self, event: QPaintEvent) -> None:
        painter = QPainter(self)
        painter.setRenderHint(QPainter.RenderHint.Antialiasing)
        painter.fillRect(self.rect(), QColor(36, 36, 40))
        r = self._plot_rect()
        painter.fillRect(r, QColor(24, 24, 28))
        lo, hi = self._view_range()
        if self.histogram_pending:
            painter.setPen(QColor(140, 140, 150))
            painter.drawText(r, Qt.AlignmentFlag.AlignCenter, "computing histogram…")
        elif self.histogram is not None and self.histogram_edges is not None and self.histogram.size:
            counts = np.log1p(self.histogram) if self.log_histogram else self.histogram.astype(np.float64)
            top = counts.max() or 1.0
            painter.setPen(Qt.PenStyle.NoPen)
            painter.setBrush(QColor(90, 90, 100))
            edges = self.histogram_edges
            for c, x0, x1 in zip(counts, self.x_of(edges[:-1]), self.x_of(edges[1:])):
                h = c / top * r.height()
                painter.drawRect(QRectF(x0, r.bottom() - h, max(x1 - x0, 1.0), h))
        if self.log_floor is not None:
            self._paint_log_ticks(painter, r)
        path = QPainterPath()
        for i, (s, rho) in enumerate(zip(self.scalars, self.extinction)):
            p = self.to_screen(s, rho)
            path.moveTo(p) if i == 0 else path.lineTo(p)
        painter.setPen(QPen(QColor(240, 240, 240), 1.5))
        painter.setBrush(Qt.BrushStyle.NoBrush)
        painter.drawPath(path)
        for i, (s, rho) in enumerate(zip(self.scalars, self.extinction)):
            c = self.colors[i]
            painter.setBrush(QColor.fromRgbF(*np.clip(c, 0, 1)))
            painter.setPen(QPen(QColor(255, 220, 0) if i == self.selected else QColor(250, 250, 250), 1.5))
            painter.drawEllipse(self.to_screen(s, rho), POINT_RADIUS, POINT_RADIUS)
        bar = QRectF(r.left(), r.bottom() + MARGIN, r.width(), COLOR_BAR_HEIGHT)
        row = self.bar_colors(int(round(bar.width())))
        data = row.tobytes()               # kept while the image that reads it is drawn
        image = QImage(data, row.shape[0], 1, 3 * row.shape[0], QImage.Format.Format_RGB888)
        painter.drawImage(bar, image)      # one texel a pixel column: no smoothing to blur it
        painter.end()

    def bar_colors(self, columns: int) -> np.ndarray:
        """(columns, 3) uint8: the color bar's color at each pixel column's centre, the control points' colors
        interpolated along the axis (linear, or log10 with ``log_floor``) as the volume is colored. Qt's
        QLinearGradient looked colors up in a 1024-entry table, a third of a pixel apart on a 338-pixel bar, so on a
        steep stretch (the neghip flow's 192 .. 255 under a log axis: ~8 levels a pixel) a column showed a color 3
        levels off its centre's at one bar width and not another (issue #28: seen when the dock lost its scroll bar)."""
        lo, hi = self._view_range()
        stops = np.clip(axis_fraction(self.scalars, lo, hi, self.log_floor), 0.0, 1.0)
        centres = (np.arange(max(columns, 1)) + 0.5) / max(columns, 1)
        rgb = np.stack([np.interp(centres, stops, np.clip(self.colors[:, k], 0.0, 1.0)) for k in range(3)], axis=1)
        return np.ascontiguousarray(np.rint(rgb * 255.0).astype(np.uint8))

    def _paint_log_ticks(self, painter: QPainter, r: QRectF) -> None:
        """The log axis's ticks (``log_ticks`` from the floor to the top of the range): a line and its value each."""
        lo, hi = self._view_range()
        floor = max(lo, float(self.log_floor or lo))
        painter.setPen(QPen(QColor(110, 110, 125), 1.0))
        for tick, x in zip(log_ticks(floor, hi), self.x_of(log_ticks(floor, hi))):
            painter.drawLine(QPointF(float(x), r.top()), QPointF(float(x), r.bottom()))
            painter.drawText(QPointF(float(x) + 2.0, r.top() + 11.0), f"{tick:g}")

    # -- interaction ------------------------------------------------------------------------------------------------
    def mousePressEvent(self, event: QMouseEvent) -> None:
        pos = event.position()
        index = self.point_at(pos)
        if event.button() == Qt.MouseButton.RightButton:
            if index is not None and len(self.scalars) > MIN_POINTS:
                self._remove(index)
                self.editFinished.emit("Remove control point")
            return
        if event.button() != Qt.MouseButton.LeftButton:
            return
        if index is None:
            index = self._insert(*self.from_screen(pos))
            self.pointsEdited.emit()
        self.selected = index
        self._dragging = True
        self.update()

    def mouseMoveEvent(self, event: QMouseEvent) -> None:
        if not self._dragging or self.selected is None:
            return
        s, rho = self.from_screen(event.position())
        i = self.selected
        self.scalars[i] = moved_scalar(self.scalars, i, s)  # interior points keep their order, the ends the range
        self.extinction[i] = rho
        self.pointsEdited.emit()
        self.update()

    def mouseReleaseEvent(self, event: QMouseEvent) -> None:
        if self._dragging:
            self._dragging = False
            self.editFinished.emit("Move control point")

    def mouseDoubleClickEvent(self, event: QMouseEvent) -> None:
        index = self.point_at(event.position())
        if index is not None:
            self.colorRequested.emit(index)

    def _insert(self, s: float, rho: float) -> int:
        self.scalars, self.colors, self.extinction, i = insert_point(self.scalars, self.colors, self.extinction, s,
                                                                     rho)
        return i

    def _remove(self, index: int) -> None:
        self.scalars, self.colors, self.extinction = remove_point(self.scalars, self.colors, self.extinction, index)
        self.selected = None
        self.update()
