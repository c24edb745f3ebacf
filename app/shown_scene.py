"""What the main window's parts (``camera_bookmarks``, ``export_runs``, ``session_files``, ``scene_loading``) are
given of the scene the window shows: a ``typing.Protocol`` the window satisfies, so that each part names, with its
type, the one collaborator they all share instead of reaching into the whole window. The window alone replaces the
shown scene (a new one installed, a session saved under another name); a part reads it at the time it acts."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Any, Optional, Protocol

if TYPE_CHECKING:
    from volviz.render.controller import SceneController
    from volviz.session import Session


class ShownScene(Protocol):
    """The shown scene: its session and the file it came from (None: not saved yet), its datasets, the controller
    that draws it (None before the first scene and after closing), the name the title shows without a session file,
    and whether it has unsaved changes."""

    session: Session
    session_path: Optional[Path]
    datasets: dict[str, Any]
    controller: Optional[SceneController]
    title: str
    dirty: bool
