"""Opening files and folders dropped on the window: a file opens as File > Open does (data or session), a folder
opens as a dataset of its own (an OpenFOAM case folder, say). Only local paths are taken; the first one dropped is
opened (a scene shows one file at a time)."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Callable, Optional

from PySide6.QtCore import QEvent, QMimeData, QObject
from PySide6.QtWidgets import QWidget


def dropped_path(mime: Optional[QMimeData]) -> Optional[Path]:
    """The first local file or folder among the URLs of a drag (None: nothing volviz can open)."""
    if mime is None or not mime.hasUrls():
        return None
    for url in mime.urls():
        if url.isLocalFile() and url.toLocalFile():
            return Path(url.toLocalFile())
    return None


class FileDrop(QObject):
    """Event filter on the ``targets`` (the main window and its viewport): accepts drags that carry a local path and
    calls ``open_path(path)`` for a drop. The docks take no drops, so a drop on them arrives at the window; the
    viewport (pyvistaqt's) would add a dropped file as a bare mesh of its own, so its drops are taken here first."""

    def __init__(self, targets: list[QWidget], open_path: Callable[[Path], Any]) -> None:
        super().__init__(targets[0])
        self.open_path = open_path
        for target in targets:
            target.setAcceptDrops(True)
            target.installEventFilter(self)

    def eventFilter(self, watched: Any, event: Any) -> bool:
        kind = event.type()
        if kind in (QEvent.Type.DragEnter, QEvent.Type.DragMove):
            if dropped_path(event.mimeData()) is not None:
                event.acceptProposedAction()
                return True
            return False
        if kind == QEvent.Type.Drop:
            path = dropped_path(event.mimeData())
            if path is None:
                return False
            event.acceptProposedAction()
            self.open_path(path)
            return True
        return False
