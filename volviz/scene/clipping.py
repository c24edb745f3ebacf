"""The scene's clipping as settings: ``session.clip`` (JSON of ``volviz.model.clip.ClipSettings``: planes and a
box, libMini note Fig. 6) read one way for every cut (isosurfaces, PT meshes, VTK props: ``volviz.render.clipping``)."""
from __future__ import annotations

from typing import Any

from volviz.model.clip import ClipSettings

NO_CLIP: dict[str, Any] = {"planes": [], "box": None}


def clip_settings(clip: dict[str, Any] | ClipSettings | None) -> ClipSettings:
    """``session.clip`` (or None) as ClipSettings."""
    if isinstance(clip, ClipSettings):
        return clip
    return ClipSettings.from_dict(clip or NO_CLIP)
