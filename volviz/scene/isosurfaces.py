"""Any thread: an isosurface component's surfaces ready for actors (libMini note "Isosurfaces"): extracted at the
display time, cut exactly by the scene's clipping, scaled by the component's opacity, with their LOD chains.
``volviz.render.iso_actors`` makes the VTK actors from them."""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING, Optional

from volviz.jobs import ProgressCallback
from volviz.model.clip import ClipSettings
from volviz.scene.errors import SceneError
from volviz.session import Component

if TYPE_CHECKING:   # type-only imports for the signatures
    from volviz.iso import IsoSettings
    from volviz.iso.extract import IsoMesh
    from volviz.iso.lod import LodChain


@dataclass
class IsoParts:
    """An isosurface component's surfaces ready for actors (``isosurface_parts``): the extracted ones (uncut by the
    scene clipping), the shown ones (cut, opacity scaled) and the LOD chains of the shown ones."""

    meshes: list[IsoMesh]
    shown: list[IsoMesh]
    lod: Optional[list[Optional[tuple[LodChain, float]]]]   # per shown surface: its chain, triangles per pixel²
    settings: IsoSettings
    clip: ClipSettings = field(default_factory=ClipSettings)  # the scene clipping they were cut by
    opacity: float = 1.0                                 # the component opacity they were scaled by


def isosurface_parts(comp: Component, dataset: object = None, t: Optional[float] = None,
                     clip: Optional[ClipSettings] = None,
                     meshes: Optional[list[IsoMesh]] = None, progress: Optional[ProgressCallback] = None) -> IsoParts:
    """Any thread: the surfaces of an ``isosurface`` component (settings: ``volviz.iso.IsoSettings``) extracted at
    display time ``t`` (skipped when ``meshes`` are known), cut exactly by the scene's ``clip`` (``session.clip``; None:
    none) on top of the component's own clipping, scaled by its opacity, with their LOD chains."""
    from volviz.iso import IsoSettings, build_lod, prepare   # the iso kernels: only for isosurfaces (start-up)
    from volviz.iso.clip import clip_isosurfaces

    try:
        settings = IsoSettings.from_dict(comp.settings)
    except ValueError as exc:
        raise SceneError(f"component {comp.id!r}: {exc}") from None
    if not settings.styles:
        raise SceneError(f"component {comp.id!r}: settings.styles lists no iso-values")
    if meshes is None:
        meshes = list(prepare(dataset, settings, t, progress=progress).meshes)
    scene_clip = ClipSettings() if clip is None else clip
    shown = clip_isosurfaces(meshes, scene_clip) if scene_clip.all_planes() else list(meshes)
    if comp.opacity < 1.0:  # the component's opacity scales every surface's
        shown = [replace(m, style=replace(m.style, opacity=m.style.opacity * comp.opacity)) for m in shown]
    fit_spectra(shown)
    lod = None  # LOD chains of the shown surfaces (the CPU modes draw them view-dependently)
    if settings.lod:
        lod = [(build_lod(m), settings.triangles_per_pixel2) if m.n_triangles else None for m in shown]
    return IsoParts(list(meshes), shown, lod, settings, scene_clip, float(comp.opacity))


def fit_spectra(meshes: list[IsoMesh]) -> None:
    """Any thread: the iso-spectrum fits of the translucent ``meshes``' opacities (``volviz.iso.fit_spectrum``, cached
    per opacity), made where the surfaces are, so that the actors and the CPU compositor that use them find them in
    the cache: the first fit imports SciPy's optimizer, a stall on the GUI thread that makes the actors (issue #28)."""
    from volviz.iso import fit_spectrum   # the iso kernels: only for isosurfaces (start-up)

    for opacity in {float(m.style.opacity) for m in meshes}:
        if 0.0 < opacity < 1.0:
            fit_spectrum(opacity)
