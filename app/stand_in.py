"""While the shown data's scene is rebuilt (another renderer, backend, array or setting), the viewport keeps showing
its last frame instead of going blank: the frame is grabbed before the old scene is cleared and drawn over the
viewport as an image (``volviz.render.image_overlay.ImageOverlay``, which volviz's own views hide while they read
the opaque depth) until the new scene's first views are shown. Changing the renderer of the Blunt Fin left the
viewport without its volume for 1.4 s."""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from PySide6.QtCore import QTimer

LONGEST_MS = 30_000   # a rebuild whose first views never settle (an error shown meanwhile) drops the frame anyway


class StandInFrame:
    """``grab()`` the shown frame, ``show()`` it over the viewport once the old scene is cleared, ``drop()`` it when
    the new scene's first views are shown."""

    def __init__(self, plotter: Any) -> None:
        self.plotter = plotter
        self.frame: Optional[np.ndarray] = None
        self.overlay: Any = None

    def grab(self) -> None:
        self.drop()
        if self.plotter.ren_win is None:
            return
        rgb = np.asarray(self.plotter.screenshot(None, return_img=True))[..., :3]
        self.frame = np.concatenate([rgb, np.full(rgb.shape[:2] + (1,), 255, np.uint8)], axis=2)

    def show(self) -> None:
        if self.frame is None:
            return
        from volviz.render.image_overlay import ImageOverlay

        self.overlay = ImageOverlay(self.plotter)
        self.overlay.show(self.frame, render=False)
        self.frame = None
        overlay = self.overlay
        QTimer.singleShot(LONGEST_MS, lambda: self.drop() if self.overlay is overlay else None)

    def drop(self) -> None:
        self.frame = None
        overlay, self.overlay = self.overlay, None
        if overlay is not None and self.plotter.ren_win is not None:   # (a closed window has no renderers left)
            overlay.remove()
            self.plotter.interactor.update()   # one repaint without it

    @property
    def shown(self) -> bool:
        return self.overlay is not None
