"""The probe tool: the value, position and voxel (or cell and point) under the mouse cursor, shown in the status bar
as the mouse moves over the viewport (``volviz.render.probe_pick``), and pinned with a click (a click without a
drag) to the Probe dock's list, which Clear empties. What is under a resting cursor is probed again when the scene
is replaced or rebuilt (a file opened with a key or a drop, another array) and when the display time changes (a
time step, playback): the status bar never names a value of data no longer shown."""
from __future__ import annotations

from typing import Any, Optional

from PySide6.QtCore import QEvent, QObject, QPoint, Qt, QTimer
from PySide6.QtWidgets import QDockWidget, QLabel, QListWidget, QPushButton, QVBoxLayout, QWidget

PROBE_DELAY_MS = 30       # moves are coalesced: one probe for the last position after the mouse rests this long
CLICK_SLOP_PX = 3         # a press and release this close is a click (pins), farther is a drag (orbits)


class ProbeTool(QObject):
    """Watches ``window.plotter.interactor``'s mouse events (it never consumes them): ``label`` in the status bar
    shows the last probe, ``pinned`` (in ``dock``) the clicked ones. ``last`` is the last ``ProbeResult`` or None."""

    def __init__(self, window: Any) -> None:
        super().__init__(window)
        self.window = window
        self.last: Optional[Any] = None
        self.label = QLabel("")
        self.label.setObjectName("probeLabel")
        window.statusBar().addPermanentWidget(self.label)
        self.pinned = QListWidget()
        clear = QPushButton("Clear")
        clear.clicked.connect(self.pinned.clear)
        self.clear_button = clear
        body = QWidget()
        column = QVBoxLayout(body)
        column.addWidget(self.pinned)
        column.addWidget(clear)
        self.dock = QDockWidget("Probe", window)
        self.dock.setObjectName("probeDock")
        self.dock.setWidget(body)
        window.addDockWidget(Qt.DockWidgetArea.RightDockWidgetArea, self.dock)
        self.dock.hide()               # shown at the first pin, and from View > Probe
        self._pos: Optional[QPoint] = None
        self._press: Optional[QPoint] = None
        self.timer = QTimer(self, singleShot=True, interval=PROBE_DELAY_MS)
        self.timer.timeout.connect(self.probe_now)
        window.plotter.interactor.installEventFilter(self)
        window.scene_tree.populated.connect(self.probe_again)   # after the new scene's docks are filled
        window.timeline.timeChanged.connect(self.probe_again)   # the timer runs after the scene took the time

    def probe_again(self, *_: Any) -> None:
        """The data under the cursor changed: probe the resting cursor again (a moment later, coalesced)."""
        if self._pos is not None and self.label.text():
            self.timer.start()

    def eventFilter(self, watched: Any, event: Any) -> bool:  # noqa: N802 (Qt's name)
        kind = event.type()
        if kind == QEvent.Type.MouseMove and event.buttons() == Qt.MouseButton.NoButton:
            self._pos = event.position().toPoint()
            self.timer.start()
        elif kind == QEvent.Type.MouseButtonPress and event.button() == Qt.MouseButton.LeftButton:
            self._press = event.position().toPoint()
        elif kind == QEvent.Type.MouseButtonRelease and event.button() == Qt.MouseButton.LeftButton:
            pos, press = event.position().toPoint(), self._press
            self._press = None
            if press is not None and (pos - press).manhattanLength() <= CLICK_SLOP_PX:
                self._pos = pos
                self.pin()
        elif kind == QEvent.Type.Leave:
            self.timer.stop()
            self._pos = None
            self.label.setText("")
        return False

    def probe_now(self) -> Optional[Any]:
        """Probe at the last mouse position and show the result in the status bar."""
        window = self.window
        if self._pos is None or window.controller is None:
            return None
        from volviz.render.probe_pick import probe_scene

        widget = window.plotter.interactor
        ratio = widget.devicePixelRatioF()
        height = window.plotter.ren_win.GetSize()[1]
        x, y = self._pos.x() * ratio, height - 1 - self._pos.y() * ratio   # VTK counts rows from the bottom
        self.last = probe_scene(window.controller, x, y)
        self.label.setText("Probe: nothing visible under the cursor" if self.last is None
                           else f"Probe: {self.last.text()}")
        return self.last

    def pin(self) -> None:
        """Add what is under the cursor now to the pinned list (and show the dock)."""
        hit = self.probe_now()
        if hit is None:
            return
        self.pinned.addItem(hit.text())
        self._place_dock()
        self.dock.show()
        self.dock.raise_()

    def _place_dock(self) -> None:
        """Before its first showing the dock goes behind a tab of the Scene dock's group (unless the user's layout put
        it in a group already): shown below that group, it took 250 pixels of the column's height from the transfer
        function dock, whose Undo, Redo, Import and Export buttons then scrolled out of view (issue #28)."""
        window, scene = self.window, getattr(self.window, "scene_dock", None)
        if (self.dock.isHidden() and not self.dock.isFloating() and not window.tabifiedDockWidgets(self.dock)
                and scene is not None and scene.isVisible() and not scene.isFloating()):
            window.tabifyDockWidget(scene, self.dock)
