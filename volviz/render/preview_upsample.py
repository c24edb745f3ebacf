"""A reduced-resolution CPU volume image (a preview while the camera moves) magnified to the window, each window
pixel made of the preview pixels that were cut at its own opaque depth (nearest-depth upsampling; Guthe §4.5: the
volume is cut per pixel by the opaque scene).

A preview pixel covers a block of window pixels and is cut at the nearest opaque depth of its block
(``image_overlay.block_min``). Magnified as it was, a thin line in front of the volume (the outline box's near
edges) took the volume out of its whole block: a dark two-pixel staircase along the box during a drag (issue #28;
measured on the Blunt Fin at 900 x 650: 588 pixels along the box darker than both neighbours by more than 8 levels
in the preview against 26 in the still frame; 35 with this upsampling)."""
from __future__ import annotations

import numpy as np
from numba import njit, prange

__all__ = ["DEPTH_MATCH", "upsample_preview"]

DEPTH_MATCH = 0.01   # a preview pixel serves a window pixel whose opaque depth is within this share of its cut depth


@njit(cache=True, nogil=True, inline="always")
def _matches(cut: float, depth: float) -> bool:
    """Whether a preview pixel cut at ``cut`` was made for a window pixel of opaque depth ``depth``."""
    if cut == depth:                         # both unlimited (no opaque geometry) or equal
        return True
    if not (np.isfinite(cut) and np.isfinite(depth)):
        return False
    return abs(cut - depth) <= DEPTH_MATCH * abs(depth)


@njit(cache=True, nogil=True, parallel=True)
def _upsample(image: np.ndarray, cut: np.ndarray, depth: np.ndarray, out: np.ndarray) -> None:
    h, w = cut.shape
    big_h, big_w = depth.shape
    for y in prange(big_h):
        py = min(max((y + 0.5) * h / big_h - 0.5, 0.0), h - 1.0)
        r0 = int(np.floor(py))
        r1 = min(r0 + 1, h - 1)
        fy = py - r0
        own_r = min((y * h) // big_h, h - 1)
        for x in range(big_w):
            px = min(max((x + 0.5) * w / big_w - 0.5, 0.0), w - 1.0)
            c0 = int(np.floor(px))
            c1 = min(c0 + 1, w - 1)
            fx = px - c0
            d = depth[y, x]
            total = 0.0
            acc = np.zeros(4)
            for r, c, wt in ((r0, c0, (1.0 - fy) * (1.0 - fx)), (r0, c1, (1.0 - fy) * fx),
                             (r1, c0, fy * (1.0 - fx)), (r1, c1, fy * fx)):
                if _matches(cut[r, c], d):
                    wt += 1e-9
                    total += wt
                    for k in range(4):
                        acc[k] += wt * image[r, c, k]
            if total > 0.0:
                for k in range(4):
                    out[y, x, k] = acc[k] / total
                continue
            # no neighbour was made for this depth: the preview pixel of the 3 x 3 with the nearest cut
            own_c = min((x * w) // big_w, w - 1)
            best_r, best_c, best = own_r, own_c, np.inf
            for r in range(max(own_r - 1, 0), min(own_r + 2, h)):
                for c in range(max(own_c - 1, 0), min(own_c + 2, w)):
                    gap = 0.0 if cut[r, c] == d else abs(cut[r, c] - d)
                    if gap < best:
                        best_r, best_c, best = r, c, gap
            for k in range(4):
                out[y, x, k] = image[best_r, best_c, k]


def upsample_preview(image: np.ndarray, cut: np.ndarray, depth: np.ndarray) -> np.ndarray:
    """A preview (premultiplied (h, w, 4)), each pixel cut at the opaque depth ``cut`` (h, w), magnified to the
    window's opaque ``depth`` (H, W): per window pixel, the bilinear mix of the four preview pixels around its
    centre whose cut lies within ``DEPTH_MATCH`` of its depth, else the pixel of the 3 x 3 around it with the nearest
    cut. Returns premultiplied (H, W, 4) float64."""
    img = np.ascontiguousarray(image, dtype=np.float64)
    c = np.ascontiguousarray(cut, dtype=np.float64)
    d = np.ascontiguousarray(depth, dtype=np.float64)
    if img.shape[:2] != c.shape or img.ndim != 3 or img.shape[2] != 4:
        raise ValueError(f"preview image {img.shape} does not match its cut depth {c.shape}")
    out = np.empty(d.shape + (4,), np.float64)
    _upsample(img, c, d, out)
    return out
