"""The probe: the value under the mouse cursor. Along the viewing ray through a pixel, the first sample of a regular
volume whose opacity is visible, reported with its voxel (i, j, k), the voxel's centre and its exact value from the
dataset's array (issue #28's "value under the cursor")."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

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


def probe_regular(volume: Any, origin: Any, direction: Any, tf: Any = None, component: str = "",
                  opacity: float = 1.0) -> Optional[ProbeResult]:
    """The first voxel of the regular ``volume`` (data, origin, spacing) along the ray whose opacity under ``tf``
    (a ``TransferFunction``, its extinction times ``opacity``) over half a voxel is visible; without ``tf`` the first
    voxel the ray enters. Samples every half of the smallest spacing at the nearest voxel. None when nothing visible
    is hit."""
    o = np.asarray(origin, dtype=np.float64)
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    vo = np.asarray(volume.origin, dtype=np.float64)
    sp = np.asarray(volume.spacing, dtype=np.float64)
    shape = np.asarray(volume.data.shape)
    span = ray_box(o, d, vo - 0.5 * sp, vo + (shape - 0.5) * sp)     # the voxels' cells around their centres
    if span is None:
        return None
    step = 0.5 * float(sp.min())
    t = np.arange(span[0], span[1] + 1e-12, step)
    ijk = np.clip(np.rint((o + t[:, None] * d - vo) / sp).astype(np.int64), 0, shape - 1)
    values = volume.data[ijk[:, 0], ijk[:, 1], ijk[:, 2]]
    if tf is None:
        hit = 0 if len(values) else None
    else:
        _, extinction = tf.evaluate(values.astype(np.float64))
        visible = 1.0 - np.exp(-np.asarray(extinction) * float(opacity) * step) >= VISIBLE_OPACITY
        hit = int(np.argmax(visible)) if visible.any() else None
    if hit is None:
        return None
    i, j, k = (int(v) for v in ijk[hit])
    center = tuple(float(v) for v in vo + np.array([i, j, k]) * sp)
    return ProbeResult(component, float(volume.data[i, j, k]), center, voxel=(i, j, k))  # type: ignore[arg-type]
