"""Timeline dock for time series: play/pause, step, speed, loop, 4D interpolation on/off."""
from __future__ import annotations

import time
from typing import Optional

from PySide6.QtCore import Qt, QTimer, Signal
from PySide6.QtWidgets import (QCheckBox, QDoubleSpinBox, QHBoxLayout, QLabel, QPushButton, QSizePolicy, QSlider,
                               QWidget)

SLIDER_STEPS = 1000


class Timeline(QWidget):
    """Display time runs continuously at ``speed`` data-time units per second; emits ``timeChanged(t)``."""

    timeChanged = Signal(float)
    interpolationToggled = Signal(bool)

    def __init__(self, parent: Optional[QWidget] = None):
        super().__init__(parent)
        self.span = (0.0, 0.0)
        self.steps: list[float] = []
        self.time = 0.0
        self.play_button = QPushButton("Play")
        self.play_button.setCheckable(True)
        self.play_button.setToolTip("Play the time series (again: pause)")
        self.back_button = QPushButton("◀")
        self.back_button.setToolTip("Step back to the previous time step")
        self.forward_button = QPushButton("▶")
        self.forward_button.setToolTip("Step forward to the next time step")
        for button in (self.play_button, self.back_button, self.forward_button):
            button.setMaximumWidth(56)
        self.speed = QDoubleSpinBox()
        self.speed.setRange(0.01, 1000.0)
        self.speed.setValue(1.0)
        self.speed.setSuffix(" /s")
        self.speed.setToolTip("Playback speed in time steps per second")
        self.loop = QCheckBox("Loop")
        self.loop.setChecked(True)
        self.loop.setToolTip("Start again from the first step after the last one")
        self.interpolate = QCheckBox("Interpolate")
        self.interpolate.setChecked(True)
        self.interpolate.setToolTip("4D interpolation: show the data blended between time steps (off: the nearest "
                                    "step)")
        self.slider = QSlider(Qt.Orientation.Horizontal)
        self.slider.setRange(0, SLIDER_STEPS)
        self.slider.setToolTip("Display time: drag to scrub through the series")
        self.label = QLabel("no time series")
        self.setSizePolicy(QSizePolicy.Policy.Preferred, QSizePolicy.Policy.Fixed)
        row = QHBoxLayout(self)  # one row: the timeline takes little of the window's height
        row.setContentsMargins(6, 2, 6, 2)
        for button in (self.back_button, self.play_button, self.forward_button):
            row.addWidget(button)
        row.addWidget(self.slider, 1)
        for widget in (self.label, self.speed, self.loop, self.interpolate):
            row.addWidget(widget)
        self.timer = QTimer(self)
        self.timer.setInterval(33)
        self.timer.timeout.connect(self._tick)
        self._last_tick = 0.0
        self.play_button.toggled.connect(self.set_playing)
        self.back_button.clicked.connect(lambda: self.step(-1))
        self.forward_button.clicked.connect(lambda: self.step(+1))
        self.slider.valueChanged.connect(self._slider_moved)
        self.interpolate.toggled.connect(self.interpolationToggled.emit)
        self.set_steps([])

    def set_steps(self, steps: list[float]) -> None:
        self.steps = list(steps)
        enabled = len(self.steps) > 1
        for w in (self.play_button, self.back_button, self.forward_button, self.slider):
            w.setEnabled(enabled)
        if not enabled:
            self.set_playing(False)
            self.span = (0.0, 0.0)
            self.time = 0.0
            self.slider.blockSignals(True)  # back at the start, not where the previous scene's series left it
            self.slider.setValue(0)
            self.slider.blockSignals(False)
            self.label.setText("no time series")
            self.label.setToolTip("Open a series of numbered files (or a session with one) to play it here")
            return
        self.span = (self.steps[0], self.steps[-1])
        self.set_time(self.steps[0])

    def step_interval(self) -> float:
        return (self.span[1] - self.span[0]) / max(len(self.steps) - 1, 1)

    def set_playing(self, playing: bool) -> None:
        if self.play_button.isChecked() != playing:
            self.play_button.setChecked(playing)
            return
        self.play_button.setText("Pause" if playing else "Play")
        self._last_tick = time.perf_counter()
        if playing:
            self.timer.start()
        else:
            self.timer.stop()

    def step(self, direction: int) -> None:
        if not self.steps:
            return
        if direction > 0:
            later = [t for t in self.steps if t > self.time + 1e-12]
            self.set_time(later[0] if later else (self.steps[0] if self.loop.isChecked() else self.steps[-1]))
        else:
            earlier = [t for t in self.steps if t < self.time - 1e-12]
            self.set_time(earlier[-1] if earlier else (self.steps[-1] if self.loop.isChecked() else self.steps[0]))

    def set_time(self, t: float) -> None:
        lo, hi = self.span
        self.time = min(max(float(t), lo), hi)
        frac = (self.time - lo) / (hi - lo) if hi > lo else 0.0
        self.slider.blockSignals(True)
        self.slider.setValue(int(round(frac * SLIDER_STEPS)))
        self.slider.blockSignals(False)
        self.label.setText(f"t = {self.time:.4g}")
        self.label.setToolTip(f"Display time {self.time:.6g} of the steps {lo:.4g} … {hi:.4g} "
                              f"({len(self.steps)} steps)")
        self.timeChanged.emit(self.time)

    def _slider_moved(self, value: int) -> None:
        lo, hi = self.span
        self.set_time(lo + (hi - lo) * value / SLIDER_STEPS)

    def _tick(self) -> None:
        now = time.perf_counter()
        dt, self._last_tick = now - self._last_tick, now
        lo, hi = self.span
        t = self.time + dt * self.speed.value() * self.step_interval()
        if t > hi:
            if self.loop.isChecked():
                t = lo + (t - hi) % max(hi - lo, 1e-12)
            else:
                t = hi
                self.set_playing(False)
        self.set_time(t)
