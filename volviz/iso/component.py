"""The isosurface component of a scene: its session settings and the calls a scene builder makes (libMini note §4).

Session component ``{"type": "isosurface", "dataset": ..., "settings": {...}}`` with settings (all optional)::

    {"styles": [{"value": 30, "color": [0.2, 0.45, 1.0], "opacity": 0.3}, ...],
     "mode": "4pass" | "3pass" | "2pass" | "exact",  "shading": "spectrum" | "flat",
     "clip": {"planes": [{"point": [x, y, z], "normal": [nx, ny, nz]}], "box": {"lo": [...], "hi": [...]} | null},
     "lod": false, "triangles_per_pixel2": 0.25, "interpolate": true, "scalars": null}

Work split: :func:`prepare` (background worker: 4D blend, box crop, extraction, exact plane cuts, LOD chains) and
:func:`render_iso` (per view: LOD level per surface, one rasterisation of ALL components' surfaces, the scene's mode).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Optional, Sequence

from volviz.iso.clip import clip_isosurfaces, clip_volume
from volviz.model.clip import ClipSettings
from volviz.iso.composite import MODES, IsoRenderStats, render
from volviz.iso.extract import IsoMesh, IsoStyle, extract
from volviz.iso.lod import LodChain, build_lod, lod_meshes
from volviz.model.datasets import RegularVolume, TimeSeries
from volviz.model.timeseries import frame_at
from volviz.model.camera import Camera

__all__ = ["IsoSettings", "PreparedIso", "prepare", "render_iso"]


def _field(d: dict[str, Any], key: str, kind: type | tuple[type, ...], default: Any) -> Any:
    v = d.get(key, default)
    if v is not default and not isinstance(v, kind):
        raise ValueError(f"isosurface settings.{key}: expected {kind}, got {v!r}")
    return v


@dataclass
class IsoSettings:
    """Settings of one isosurface component (JSON round-trip through ``to_dict`` / ``from_dict``)."""

    styles: list[IsoStyle] = field(default_factory=list)
    mode: str = "4pass"
    shading: str = "spectrum"
    clip: ClipSettings = field(default_factory=ClipSettings)
    lod: bool = False
    triangles_per_pixel2: float = 0.25
    interpolate: bool = True
    scalars: Optional[str] = None

    def __post_init__(self) -> None:
        if self.mode not in MODES:
            raise ValueError(f"isosurface settings.mode: {self.mode!r} is not one of {MODES}")
        if self.shading not in ("spectrum", "flat"):
            raise ValueError(f"isosurface settings.shading: {self.shading!r} is not 'spectrum' or 'flat'")
        if not self.triangles_per_pixel2 > 0:
            raise ValueError("isosurface settings.triangles_per_pixel2 must be > 0")

    def to_dict(self) -> dict[str, Any]:
        return {"styles": [s.to_dict() for s in self.styles], "mode": self.mode, "shading": self.shading,
                "clip": self.clip.to_dict(), "lod": self.lod, "triangles_per_pixel2": self.triangles_per_pixel2,
                "interpolate": self.interpolate, "scalars": self.scalars}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "IsoSettings":
        if not isinstance(d, dict):
            raise ValueError(f"isosurface settings must be an object, got {d!r}")
        unknown = set(d) - {"styles", "mode", "shading", "clip", "lod", "triangles_per_pixel2", "interpolate",
                            "scalars"}
        if unknown:
            raise ValueError(f"isosurface settings: unknown keys {sorted(unknown)}")
        styles = []
        for i, s in enumerate(_field(d, "styles", list, [])):
            try:
                styles.append(IsoStyle.from_dict(s))
            except (KeyError, TypeError, ValueError) as exc:
                raise ValueError(f"isosurface settings.styles[{i}]: {exc}") from None
        try:
            clip = ClipSettings.from_dict(_field(d, "clip", dict, {"planes": [], "box": None}))
        except ValueError as exc:
            raise ValueError(f"isosurface settings.clip: {exc}") from None
        return cls(styles, _field(d, "mode", str, "4pass"), _field(d, "shading", str, "spectrum"), clip,
                   bool(_field(d, "lod", bool, False)), float(_field(d, "triangles_per_pixel2", (int, float), 0.25)),
                   bool(_field(d, "interpolate", bool, True)), _field(d, "scalars", (str, type(None)), None))


@dataclass
class PreparedIso:
    """Result of :func:`prepare`: the cut surfaces, and their LOD chains when LOD is on."""

    meshes: list[IsoMesh]
    chains: list[LodChain] | None
    time: float | None = None


def prepare(dataset: Any, settings: IsoSettings, t: float | None = None,
            progress: Optional[Callable[[float, str], None]] = None) -> PreparedIso:
    """Background part: the volume at display time ``t`` (4D blend), box crop, extraction, plane cuts, LOD chains.

    Pass it to ``volviz.jobs.JobRunner.submit(prepare, dataset, settings, t, key=component_id)`` so a newer request
    supersedes a stale one (``volviz.iso.animate.IsoAnimator`` does this for playback).
    """
    vol = dataset
    if isinstance(dataset, TimeSeries):
        vol = frame_at(dataset, float(dataset.times[0] if t is None else t), interpolate=settings.interpolate)
    if isinstance(vol, RegularVolume) and settings.clip.box is not None:
        vol = clip_volume(vol, ClipSettings(box=settings.clip.box))  # exact sub-grid; planes cut the surfaces
    meshes = extract(vol, settings.styles, scalars=settings.scalars, progress=progress)
    if settings.clip.all_planes():
        meshes = clip_isosurfaces(meshes, settings.clip)
    chains = [build_lod(m) for m in meshes] if settings.lod else None
    return PreparedIso(meshes, chains, t)


def render_iso(prepared: Sequence[PreparedIso], settings: Sequence[IsoSettings] | IsoSettings, camera: Camera,
               size: tuple[int, int] = (512, 512), mode: str | None = None,
               background: Sequence[float] = (0.0, 0.0, 0.0, 0.0)) -> tuple[Any, IsoRenderStats]:
    """Per view: all components' surfaces (LOD chosen per surface) pooled into ONE set of passes (note §4).

    ``mode`` defaults to the first component's; shading likewise. Returns the premultiplied float RGBA image
    (H, W, 4), row 0 at the top, and its statistics (seconds, triangles, triangles drawn, fragments).
    """
    sets = [settings] * len(prepared) if isinstance(settings, IsoSettings) else list(settings)
    if len(sets) != len(prepared):
        raise ValueError("one IsoSettings per prepared component is needed")
    meshes: list[IsoMesh] = []
    for p, s in zip(prepared, sets):
        if p.chains is not None:
            meshes.extend(lod_meshes(p.chains, camera, size, s.triangles_per_pixel2))
        else:
            meshes.extend(p.meshes)
    first = sets[0] if sets else IsoSettings()
    return render(meshes, camera, size, mode or first.mode, background, first.shading)
