"""Fly-through mode for the viewport: WASD/arrow keys move, Q/E (or PgDn/PgUp) sink and rise, mouse drag looks
around, +/- change speed. The motion itself is volviz.render.camera_path.FlyNavigator (Qt-free).

Nothing here draws: each step (a key press or auto-repeat, a mouse look) asks for one repaint, which Qt merges with
the others asked for before it is drawn, so a slow frame makes the flight coarser, never the window stall behind a
queue of renders (one synchronous render per key event held the event loop for seconds on the Yukon scene).

A movement key counts as held from its press to its release by the user (``held``; the keyboard's auto-repeat sends
presses, and on X11 releases too, marked as auto-repeated), so that a long frame on the GUI thread, which delays the
next repeat past the window's settle time, is not taken for the end of the flight.

While flying, the viewport's frames are drawn at a reduced resolution and magnified to it (``frames``, a
``ReducedFrames``: each step starts them; the window ends them once the views' full-size updates after the flight's
stop are shown)."""
from __future__ import annotations

from typing import Any, Callable, Optional

from PySide6.QtCore import QEvent, QObject, Qt
from PySide6.QtGui import QKeyEvent, QMouseEvent

from volviz.render.camera_path import FlyNavigator

from .reduced_frames import ReducedFrames

MOVES: dict[int, tuple[int, int, int]] = {  # by key code (``QKeyEvent.key()``; a ``Qt.Key`` is an int)
    Qt.Key.Key_W: (1, 0, 0), Qt.Key.Key_Up: (1, 0, 0),
    Qt.Key.Key_S: (-1, 0, 0), Qt.Key.Key_Down: (-1, 0, 0),
    Qt.Key.Key_D: (0, 1, 0), Qt.Key.Key_Right: (0, 1, 0),
    Qt.Key.Key_A: (0, -1, 0), Qt.Key.Key_Left: (0, -1, 0),
    Qt.Key.Key_E: (0, 0, 1), Qt.Key.Key_PageUp: (0, 0, 1),
    Qt.Key.Key_Q: (0, 0, -1), Qt.Key.Key_PageDown: (0, 0, -1),
}
STEP_SECONDS = 0.05   # one key press (or auto-repeat) moves this much flight time
LOOK_DEGREES_PER_PIXEL = 0.2


class FlyMode(QObject):
    """Event filter on the viewport widget. While enabled it consumes navigation keys and mouse drags, so VTK's own
    key bindings (w = wireframe, q = quit, ...) never fire in fly mode."""

    def __init__(self, plotter: Any, on_camera_moved: Optional[Callable[[], None]] = None):
        super().__init__(plotter.interactor)
        self.plotter = plotter
        self.navigator = FlyNavigator()
        self.enabled = False
        self.on_camera_moved = on_camera_moved
        self._last_mouse: Optional[Any] = None
        self.steps = 0                   # camera steps made (key presses and repeats, mouse looks)
        self._held: set[int] = set()     # movement keys pressed and not yet released by the user
        self.frames = ReducedFrames(plotter)   # the flight's frames at a reduced resolution
        plotter.interactor.installEventFilter(self)

    @property
    def held(self) -> bool:
        """Whether a movement key is held down (the flight goes on, however long since its last step)."""
        return self.enabled and bool(self._held)

    def set_enabled(self, enabled: bool, scene_size: float = 1.0) -> None:
        self.enabled = bool(enabled)
        self._held.clear()
        if not enabled:
            self.frames.stop()
        if enabled:
            self.navigator.speed = max(scene_size, 1e-9) * 0.25  # cross a quarter of the scene per second

    def set_bounds(self, bounds: Optional[Any]) -> None:
        """Keep the eye inside ``bounds`` (xmin, xmax, ymin, ymax, zmin, zmax; None: anywhere)."""
        self.navigator.bounds = None if bounds is None else tuple(float(v) for v in bounds)

    def set_ground(self, ground: Optional[Callable[[float, float], float]], clearance: float = 0.0,
                   obstacle: Optional[Callable[..., Optional[float]]] = None) -> None:
        """Keep the eye ``clearance`` above ``ground(x, y)`` and short of ``obstacle`` (opaque geometry)."""
        self.navigator.ground = ground
        self.navigator.clearance = clearance
        self.navigator.obstacle = obstacle

    def _camera(self) -> Any:
        from volviz.render.vtk_scene import camera_state

        return camera_state(self.plotter)

    def _apply(self, cam: Any) -> None:
        from volviz.render.vtk_scene import apply_camera

        apply_camera(self.plotter, cam)
        self.steps += 1
        self.frames.start()
        self.plotter.interactor.update()  # one repaint, merged with any other asked for before it is drawn
        if self.on_camera_moved is not None:
            self.on_camera_moved()

    def eventFilter(self, watched: QObject, event: QEvent) -> bool:
        if not self.enabled:
            return False
        kind = event.type()
        if kind == QEvent.Type.KeyPress and isinstance(event, QKeyEvent):
            key = event.key()
            if key in MOVES:   # each press and auto-repeat: one step (the repaints merge)
                self._held.add(key)
                f, r, u = MOVES[key]
                self._apply(self.navigator.move(self._camera(), f, r, u, STEP_SECONDS))
                return True
            if key in (Qt.Key.Key_Plus, Qt.Key.Key_Equal):
                self.navigator.speed *= 1.5
                return True
            if key == Qt.Key.Key_Minus:
                self.navigator.speed /= 1.5
                return True
            return True  # no VTK key bindings while flying
        if kind == QEvent.Type.KeyRelease:
            if isinstance(event, QKeyEvent) and not event.isAutoRepeat():   # the user let go
                self._held.discard(event.key())
            return True
        if kind == QEvent.Type.FocusOut:   # a key released elsewhere sends no release here
            self._held.clear()
            return False
        if kind == QEvent.Type.MouseButtonPress and isinstance(event, QMouseEvent):
            self._last_mouse = event.position()
            return True
        if kind == QEvent.Type.MouseMove and self._last_mouse is not None and isinstance(event, QMouseEvent):
            pos = event.position()
            dx, dy = pos.x() - self._last_mouse.x(), pos.y() - self._last_mouse.y()
            self._last_mouse = pos
            self._apply(self.navigator.look(self._camera(), dx * LOOK_DEGREES_PER_PIXEL, -dy * LOOK_DEGREES_PER_PIXEL))
            return True
        if kind == QEvent.Type.MouseButtonRelease:
            self._last_mouse = None
            return True
        return False
