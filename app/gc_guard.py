"""Run Python's cyclic garbage collector on the GUI thread only.

Automatic collection runs in whichever thread happens to allocate. When a background job triggers it, Qt widgets and
VTK render windows that sit in reference cycles are destroyed on that worker thread, and Qt or the OpenGL driver
aborts the process (seen in our GUI tests). The usual remedy in Qt applications: turn automatic collection off and
collect from a timer on the GUI thread, generation by generation when the counts call for it.
"""
from __future__ import annotations

import gc
from typing import Optional

from PySide6.QtCore import QObject, QTimer


class GuiThreadCollector(QObject):
    def __init__(self, parent: Optional[QObject] = None, interval_ms: int = 500):
        super().__init__(parent)
        self.thresholds = gc.get_threshold()
        gc.disable()
        self.timer = QTimer(self)
        self.timer.timeout.connect(self.check)
        self.timer.start(interval_ms)

    def freeze_long_lived(self) -> None:
        """Collect once, then move every surviving object (modules, classes, widgets: ~300,000 once the window
        exists) to the permanent generation. A full collection had to scan them all every few seconds, a blocked event
        loop each time, longer under load (the responsiveness test's > 100 ms gaps; docs/bench/docstring-figures.md).
        Called once, when the window is built; cycles made later are still collected."""
        gc.collect()
        gc.freeze()

    def unfreeze(self) -> None:
        """Undo ``freeze_long_lived`` (the window closes: its frozen objects may now be garbage)."""
        gc.unfreeze()

    def check(self) -> None:
        counts = gc.get_count()
        if counts[0] > self.thresholds[0]:
            generation = 0
            if counts[1] > self.thresholds[1]:
                generation = 1
                if counts[2] > self.thresholds[2] and not self.interacting:
                    generation = 2
            gc.collect(generation)

    #: set while the user drags the camera: a full collection (tens of ms, scanning every object the scene made
    #: after ``freeze_long_lived``) waits for the end of the interaction, young generations are still collected
    interacting = False
