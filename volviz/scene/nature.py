"""Any thread: the natural scene (terrain, ground fog, clouds, sky of the nature seeds) of a session's visible
nature components, prepared: maps read into height fields, fog prisms, cloud volumes and lighting. The render
layer's ``NatureView`` / ``GLNatureView`` show it."""
from __future__ import annotations

from typing import TYPE_CHECKING, Optional

from volviz.scene.datasets import NATURE_TYPES
from volviz.scene.errors import SceneError
from volviz.session import Session

if TYPE_CHECKING:   # type-only imports for the signatures
    from volviz.nature.nature_scene import NatureScene
    from volviz.scene.datasets import LoadedDataset


def prepare_nature(session: Session, datasets: dict[str, LoadedDataset]) -> Optional[NatureScene]:
    """Any thread: the NatureScene of the session's visible terrain / fog / clouds / sky components (None when it has
    none): maps read into height fields, fog prisms, cloud volumes and lighting; ``NatureView`` shows it."""
    components = [c for c in session.components if c.visible and c.type in NATURE_TYPES]
    if not components:
        return None
    from volviz.nature.nature_scene import scene_from_components   # heavy (the nature kernels): only when shown

    try:
        scene = scene_from_components(components, datasets)
    except (ValueError, KeyError) as exc:
        raise SceneError(f"natural scene: {exc}") from None
    scene.finalize()
    return scene
