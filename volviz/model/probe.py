"""The probe: the value under the mouse cursor. Along the viewing ray through a pixel, the first sample of a regular
volume whose opacity is visible, reported with its voxel (i, j, k), the voxel's centre and its exact value from the
dataset's array (issue #28's "value under the cursor")."""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Optional, Protocol, Sequence

import numpy as np

if TYPE_CHECKING:   # type-only imports for the signatures
    import numpy.typing as npt

    from volviz.model.clip import ClipSettings
    from volviz.model.datasets import RegularVolume

class Extinction(Protocol):
    """What the probe needs of a transfer function (``volviz.optics.TransferFunction``, a layer above the model):
    ``evaluate(scalars)`` -> (rgb, extinction)."""

    def evaluate(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...


VISIBLE_OPACITY = 0.01     # a sample whose opacity over half a voxel reaches this is what the user sees first


@dataclass(frozen=True)
class ProbeResult:
    """What the probe found: the value, where, and which voxel (regular volumes) or cell and point (meshes)."""

    component: str
    value: float
    position: tuple[float, float, float]
    voxel: Optional[tuple[int, int, int]] = None
    cell: Optional[int] = None
    point: Optional[int] = None

    def text(self) -> str:
        """One line for the status bar and the pinned list."""
        where = ", ".join(f"{v:.4g}" for v in self.position)
        ids = (f"voxel ({', '.join(str(i) for i in self.voxel)})" if self.voxel is not None
               else f"cell {self.cell}" + ("" if self.point is None else f", point {self.point}"))
        return f"{self.component}: value {self.value:.6g} at ({where}), {ids}"


def ray_box(origin: np.ndarray, direction: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> Optional[tuple[float, float]]:
    """The parameters (t0, t1), t0 >= 0, where the ray ``origin + t * direction`` is inside the box; None if it
    misses."""
    with np.errstate(divide="ignore", invalid="ignore"):
        t_a = (lo - origin) / direction
        t_b = (hi - origin) / direction
    t_near = np.where(direction == 0, np.where((origin >= lo) & (origin <= hi), -np.inf, np.inf), np.minimum(t_a, t_b))
    t_far = np.where(direction == 0, np.where((origin >= lo) & (origin <= hi), np.inf, -np.inf), np.maximum(t_a, t_b))
    t0, t1 = max(float(t_near.max()), 0.0), float(t_far.min())
    return (t0, t1) if t1 >= t0 else None


def clip_span(origin: np.ndarray, direction: np.ndarray, clip: Optional[ClipSettings],
              span: Optional[tuple[float, float]]) -> Optional[tuple[float, float]]:
    """The part of the ray's ``span`` (t0, t1) that ``clip`` (``volviz.model.clip.ClipSettings``: planes and box,
    each keeping ``(x - point) . normal >= 0``) keeps: one interval, the kept region being convex; None: nothing."""
    if span is None or clip is None:
        return span
    t0, t1 = span
    for plane in clip.all_planes():
        n = np.asarray(plane.normal, dtype=np.float64)
        num, den = float((origin - np.asarray(plane.point)) @ n), float(direction @ n)
        if den > 0:
            t0 = max(t0, -num / den)
        elif den < 0:
            t1 = min(t1, -num / den)
        elif num < 0:
            return None
    return (t0, t1) if t1 >= t0 else None


def ray_voxels(origin: npt.ArrayLike, direction: npt.ArrayLike, grid_origin: npt.ArrayLike, spacing: npt.ArrayLike,
               shape: tuple[int, int, int],
               clip: Optional[ClipSettings] = None) -> Optional[tuple[np.ndarray, float]]:
    """The voxels (n, 3) of a regular grid (sample ``(i, j, k)`` at ``grid_origin + (i, j, k) * spacing``) nearest
    the samples of the ray ``origin + t * direction`` (unit) every half of the smallest spacing, front to back,
    over the voxels' cells around their centres and what ``clip`` keeps (``clip_span``), and that step; None when
    the ray misses them."""
    o = np.asarray(origin, dtype=np.float64)
    d = np.asarray(direction, dtype=np.float64)
    vo = np.asarray(grid_origin, dtype=np.float64)
    sp = np.asarray(spacing, dtype=np.float64)
    n = np.asarray(shape, dtype=np.int64)
    span = clip_span(o, d, clip, ray_box(o, d, vo - 0.5 * sp, vo + (n - 0.5) * sp))
    if span is None:
        return None
    step = 0.5 * float(sp.min())
    t = np.arange(span[0], span[1] + 1e-12, step)
    return np.clip(np.rint((o + t[:, None] * d - vo) / sp).astype(np.int64), 0, n - 1), step


def first_visible(values: np.ndarray, tf: Optional[Extinction], opacity: float, step: float) -> Optional[int]:
    """The index of the first of ``values`` (samples ``step`` apart) whose opacity under ``tf`` (its extinction
    times ``opacity``) over the step reaches ``VISIBLE_OPACITY``; without ``tf`` the first sample; None: none."""
    if not len(values):
        return None
    if tf is None:
        return 0
    _, extinction = tf.evaluate(np.asarray(values, dtype=np.float64))
    visible = 1.0 - np.exp(-np.asarray(extinction) * float(opacity) * step) >= VISIBLE_OPACITY
    return int(np.argmax(visible)) if visible.any() else None


def probe_regular(volume: RegularVolume, origin: npt.ArrayLike, direction: npt.ArrayLike,
                  tf: Optional[Extinction] = None, component: str = "",
                  opacity: float = 1.0, clip: Optional[ClipSettings] = None) -> Optional[ProbeResult]:
    """The first voxel of the regular ``volume`` (data, origin, spacing) along the ray whose opacity under ``tf``
    (a ``TransferFunction``, its extinction times ``opacity``) over half a voxel is visible; without ``tf`` the first
    voxel the ray enters. Samples every half of the smallest spacing at the nearest voxel, in the part ``clip``
    keeps (``ray_voxels``). None when nothing visible is hit."""
    d = np.asarray(direction, dtype=np.float64)
    march = ray_voxels(origin, d / np.linalg.norm(d), volume.origin, volume.spacing, volume.data.shape, clip)
    if march is None:
        return None
    ijk, step = march
    hit = first_visible(volume.data[ijk[:, 0], ijk[:, 1], ijk[:, 2]], tf, opacity, step)
    if hit is None:
        return None
    return voxel_result(component, float(volume.data[tuple(ijk[hit])]), ijk[hit], volume.origin, volume.spacing)


def voxel_result(component: str, value: float, ijk: Sequence[int] | np.ndarray, grid_origin: npt.ArrayLike,
                 spacing: npt.ArrayLike) -> ProbeResult:
    """The probe's answer at voxel ``ijk`` of a regular grid: its value, its centre and its index."""
    i, j, k = (int(v) for v in ijk)
    center = np.asarray(grid_origin, dtype=np.float64) + np.array([i, j, k]) * np.asarray(spacing, dtype=np.float64)
    return ProbeResult(component, value, tuple(float(v) for v in center), voxel=(i, j, k))  # type: ignore[arg-type]
