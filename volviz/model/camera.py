"""A small pinhole / parallel camera, consistent with VTK's vtkCamera, and its pixel rays.

Conventions (the same as VTK's): the view angle is the full *vertical* angle in degrees; the view-up vector is
orthogonalised against the direction of projection; the clipping range is (near, far) distances along the direction
of projection from the camera position; for parallel projection ``parallel_scale`` is half the image height in world
units. Pixel ``(row, col)`` of an ``(H, W)`` image has its centre at continuous pixel coordinates ``(px, py) =
(col, row)`` with row 0 at the top; normalised device coordinates are ``x = 2 (px + 0.5) / W - 1`` and
``y = 1 - 2 (py + 0.5) / H``, as VTK maps its viewport.

Every pixel ray is ``O(px, py) + t D(px, py)`` with O and D affine in (px, py) and ``D . forward = 1``, so ``t`` is the
depth along the direction of projection (clipping planes are ``t = near`` and ``t = far``).
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Protocol, Sequence, TypedDict, Union

import numpy as np

from volviz.model.extent import point_extent

if TYPE_CHECKING:   # type-only imports for the signatures
    import pyvista as pv


class VtkCamera(Protocol):
    """What ``Camera`` reads and sets of a VTK camera (a ``vtkCamera`` or ``pyvista.Camera``): the model layer names
    no VTK rendering class (tests/test_layering_rendering.py)."""

    def GetPosition(self) -> Sequence[float]: ...
    def GetFocalPoint(self) -> Sequence[float]: ...
    def GetViewUp(self) -> Sequence[float]: ...
    def GetViewAngle(self) -> float: ...
    def GetParallelProjection(self) -> int: ...
    def GetParallelScale(self) -> float: ...
    def GetClippingRange(self) -> Sequence[float]: ...
    def SetPosition(self, x: float, y: float, z: float, /) -> None: ...
    def SetFocalPoint(self, x: float, y: float, z: float, /) -> None: ...
    def SetViewUp(self, x: float, y: float, z: float, /) -> None: ...
    def SetViewAngle(self, angle: float, /) -> None: ...
    def SetParallelProjection(self, on: int, /) -> None: ...
    def SetParallelScale(self, scale: float, /) -> None: ...
    def SetClippingRange(self, near: float, far: float, /) -> None: ...
    def OrthogonalizeViewUp(self) -> None: ...


def _unit(v: np.ndarray, what: str) -> np.ndarray:
    n = float(np.linalg.norm(v))
    if not np.isfinite(n) or n == 0.0:
        raise ValueError(f"camera {what} is degenerate")
    return v / n


@dataclass
class RayBasis:
    """Affine pixel rays: ``O = o0 + px ox + py oy``, ``D = d0 + px dx + py dy`` (world units, relative to origin)."""

    o0: np.ndarray
    ox: np.ndarray
    oy: np.ndarray
    d0: np.ndarray
    dx: np.ndarray
    dy: np.ndarray
    near: float
    far: float
    parallel: bool

    def as_array(self) -> np.ndarray:
        """(6, 3) float64: o0, ox, oy, d0, dx, dy (the layout the Numba kernels take)."""
        return np.ascontiguousarray(np.stack([self.o0, self.ox, self.oy, self.d0, self.dx, self.dy]))


class CameraDict(TypedDict):
    """A camera as the session file and ``Camera.to_dict`` write it (JSON: lists for the vectors)."""

    position: list[float]
    focal_point: list[float]
    view_up: list[float]
    view_angle: float
    parallel: bool
    parallel_scale: float
    clipping_range: list[float]


@dataclass
class Camera:
    """Position, focal point, view up, vertical view angle, parallel projection and clipping range (VTK semantics).

    The three vectors may be given as any sequences of three numbers; they are kept as float64 arrays of shape (3,)."""

    position: Sequence[float] | np.ndarray = (0.0, 0.0, 1.0)
    focal_point: Sequence[float] | np.ndarray = (0.0, 0.0, 0.0)
    view_up: Sequence[float] | np.ndarray = (0.0, 1.0, 0.0)
    view_angle: float = 30.0
    parallel: bool = False
    parallel_scale: float = 1.0
    clipping_range: tuple[float, float] = field(default=(0.01, 1000.0))

    def __post_init__(self) -> None:
        self.position = np.asarray(self.position, dtype=np.float64).reshape(3)
        self.focal_point = np.asarray(self.focal_point, dtype=np.float64).reshape(3)
        self.view_up = np.asarray(self.view_up, dtype=np.float64).reshape(3)
        near, far = (float(v) for v in self.clipping_range)
        if not (near > 0 and far > near):
            raise ValueError(f"clipping range must satisfy 0 < near < far, got {self.clipping_range}")
        self.clipping_range = (near, far)
        if not 0.0 < self.view_angle < 180.0:
            raise ValueError(f"view angle must be in (0, 180) degrees, got {self.view_angle}")
        if self.parallel and not self.parallel_scale > 0:
            raise ValueError("parallel scale must be positive")

    # --- frame -------------------------------------------------------------------------------------------------
    def frame(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Orthonormal (right, up, forward) with forward from the position to the focal point."""
        f = _unit(np.subtract(self.focal_point, self.position), "direction (position == focal point)")
        r = _unit(np.cross(f, self.view_up), "view up (parallel to the direction of projection)")
        return r, np.cross(r, f), f

    def _scales(self, size: tuple[int, int]) -> tuple[float, float]:
        w, h = size
        half = self.parallel_scale if self.parallel else math.tan(math.radians(self.view_angle) / 2.0)
        return half * w / h, half

    def rays(self, size: tuple[int, int], origin: Sequence[float] | np.ndarray | None = None) -> RayBasis:
        """Affine pixel rays for an image of ``size = (W, H)``, positions relative to ``origin`` (default 0)."""
        w, h = (int(v) for v in size)
        if w < 1 or h < 1:
            raise ValueError(f"image size must be positive, got {size}")
        r, u, f = self.frame()
        hx, hy = self._scales((w, h))
        su, ou = 2.0 * hx / w, (1.0 / w - 1.0) * hx
        sv, ov = -2.0 * hy / h, (1.0 - 1.0 / h) * hy
        eye = self.position - (np.zeros(3) if origin is None else np.asarray(origin, dtype=np.float64))
        z = np.zeros(3)
        near, far = self.clipping_range
        if self.parallel:
            return RayBasis(eye + ou * r + ov * u, su * r, sv * u, f.copy(), z, z.copy(), near, far, True)
        return RayBasis(eye.copy(), z, z.copy(), f + ou * r + ov * u, su * r, sv * u, near, far, False)

    def project(self, points: np.ndarray, size: tuple[int, int]) -> np.ndarray:
        """World points (..., 3) -> (..., 3) with continuous pixel coordinates (px, py) and depth along the view."""
        r, u, f = self.frame()
        w, h = size
        hx, hy = self._scales((w, h))
        rel = np.asarray(points, dtype=np.float64) - self.position
        x, y, z = rel @ r, rel @ u, rel @ f
        if not self.parallel:
            with np.errstate(divide="ignore", invalid="ignore"):
                x, y = x / z, y / z
        px = (x / hx + 1.0) * w / 2.0 - 0.5
        py = (1.0 - y / hy) * h / 2.0 - 0.5
        return np.stack([px, py, z], axis=-1)

    # --- VTK / PyVista interop ---------------------------------------------------------------------------------
    @classmethod
    def from_pyvista(cls, camera: Union[pv.Camera, VtkCamera]) -> "Camera":
        """From a ``pyvista.Camera`` or any ``vtkCamera`` (horizontal view angles are refused)."""
        if hasattr(camera, "GetUseHorizontalViewAngle") and camera.GetUseHorizontalViewAngle():
            raise ValueError("cameras with a horizontal view angle are not supported")
        return cls(camera.GetPosition(), camera.GetFocalPoint(), camera.GetViewUp(), camera.GetViewAngle(),
                   bool(camera.GetParallelProjection()), camera.GetParallelScale(), tuple(camera.GetClippingRange()))

    def apply_to(self, vtk_camera: Union[pv.Camera, VtkCamera]) -> None:
        """Set a ``vtkCamera`` (or ``pyvista.Camera``) to this camera."""
        vtk_camera.SetPosition(*self.position)
        vtk_camera.SetFocalPoint(*self.focal_point)
        vtk_camera.SetViewUp(*self.view_up)
        vtk_camera.SetViewAngle(self.view_angle)
        vtk_camera.SetParallelProjection(bool(self.parallel))
        vtk_camera.SetParallelScale(self.parallel_scale)
        vtk_camera.SetClippingRange(*self.clipping_range)
        vtk_camera.OrthogonalizeViewUp()

    def to_dict(self) -> CameraDict:
        return {"position": list(map(float, self.position)), "focal_point": list(map(float, self.focal_point)),
                "view_up": list(map(float, self.view_up)), "view_angle": float(self.view_angle),
                "parallel": bool(self.parallel), "parallel_scale": float(self.parallel_scale),
                "clipping_range": list(self.clipping_range)}

    @classmethod
    def from_dict(cls, d: CameraDict) -> "Camera":
        near, far = d["clipping_range"]
        return cls(d["position"], d["focal_point"], d["view_up"], d["view_angle"], d["parallel"],
                   d["parallel_scale"], (near, far))

    @classmethod
    def orbit(cls, points: np.ndarray, azimuth: float = 30.0, elevation: float = 20.0, distance: float = 2.5,
              view_angle: float = 30.0, parallel: bool = False, up: Sequence[float] = (0.0, 0.0, 1.0)) -> "Camera":
        """A camera looking at the centre of ``points`` from ``distance`` bounding radii (angles in degrees)."""
        pts = np.asarray(points, dtype=np.float64).reshape(-1, 3)
        lo, hi = point_extent(pts)
        centre = 0.5 * (lo + hi)
        radius = 0.5 * float(np.linalg.norm(hi - lo)) or 1.0
        a, e = math.radians(azimuth), math.radians(elevation)
        up_v = _unit(np.asarray(up, dtype=np.float64), "up")
        side = np.array([1.0, 0.0, 0.0]) if abs(up_v[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
        b1 = _unit(side - up_v * (side @ up_v), "basis")
        b2 = np.cross(up_v, b1)
        direction = math.cos(e) * (math.cos(a) * b1 + math.sin(a) * b2) + math.sin(e) * up_v
        pos = centre + distance * radius * direction
        dist = distance * radius
        return cls(pos, centre, up_v, view_angle, parallel, radius * 1.05,
                   (max(dist - 1.5 * radius, 1e-3 * dist), dist + 1.5 * radius))
