"""Reduced-resolution drawing while the camera moves (issue #29): the size a GPU pass draws at during an interaction
and the pixel ray basis for that size.

Projected tetrahedra are fill-bound when the volume covers the window (Roettger §11.7, digest §9.10: the frame rate
falls with the pixels covered, ≈ 15 fps at 512 x 384 inside a cloud), so during a drag the fill is capped: the
volume is drawn into a target of at most ``INTERACTIVE_PIXELS`` pixels (the window's aspect kept, scale
sqrt(cap / pixels)) and upsampled bilinearly over the window; a drag at 3840x2160 then fills 1920x1080 pixels, and at
1920x1080 or less nothing changes (the same idea as VTK's ``ImageSampleDistance`` for its ray casters).
"""
from __future__ import annotations

import math

import numpy as np

from volviz.model.camera import RayBasis

__all__ = ["INTERACTIVE_PIXELS", "reduced_size", "scaled_rays"]

INTERACTIVE_PIXELS = 1920 * 1080      # the fill of an interactive frame: a 1080p window's


def reduced_size(size: tuple[int, int], max_pixels: int = INTERACTIVE_PIXELS) -> tuple[int, int]:
    """The (width, height) to draw a ``size`` window at with at most ``max_pixels`` pixels: ``size`` itself when it
    has no more, else both sides scaled by sqrt(max_pixels / pixels), rounded down (at least 1 pixel)."""
    w, h = (int(v) for v in size)
    if w < 1 or h < 1:
        raise ValueError(f"window size must be positive, got {size}")
    if max_pixels < 1:
        raise ValueError(f"the interactive pixel count must be positive, got {max_pixels}")
    if w * h <= max_pixels:
        return w, h
    scale = math.sqrt(max_pixels / (w * h))
    dw, dh = max(1, int(w * scale + 1e-9)), max(1, int(h * scale + 1e-9))
    if dw * dh > max_pixels:              # a side held at 1 pixel: the other one takes the rest of the cap
        dw, dh = (min(dw, max_pixels), 1) if dh == 1 else (1, min(dh, max_pixels))
    return dw, dh


def scaled_rays(rb: RayBasis, size: tuple[int, int], drawn: tuple[int, int]) -> RayBasis:
    """The ray basis of a ``size`` image (``Camera.rays``) re-expressed for the pixels of a ``drawn`` image covering
    the same view: drawn pixel (qx, qy) has its centre at full-size pixel ((qx + 0.5) s_x - 0.5, (qy + 0.5) s_y - 0.5)
    with s = size / drawn per axis, so the rays are exactly the full view's at those points (no aspect change from
    rounding the drawn size), and a bilinear upsampling at full-size pixel centres lines up with them."""
    sx, sy = size[0] / drawn[0], size[1] / drawn[1]

    def basis(v0: np.ndarray, vx: np.ndarray, vy: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        return v0 + (0.5 * sx - 0.5) * vx + (0.5 * sy - 0.5) * vy, sx * vx, sy * vy

    o0, ox, oy = basis(rb.o0, rb.ox, rb.oy)
    d0, dx, dy = basis(rb.d0, rb.dx, rb.dy)
    return RayBasis(o0, ox, oy, d0, dx, dy, rb.near, rb.far, rb.parallel)
