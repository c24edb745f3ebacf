"""Clipping settings (libMini note, Fig. 6): planes and a box crop, the model's part of clipping (issue #18: the bottom
layer holds them; ``volviz.iso.clip`` cuts volumes, isosurfaces and meshes with them, ``volviz.render.clipping``
gives them to VTK's mappers and the GPU passes). A plane ``(point, normal)`` keeps the half-space
``(x − point)·normal ≥ 0``; several planes keep their intersection; the box keeps ``lo ≤ x ≤ hi``. Settings are plain
JSON (``ClipSettings.to_dict`` / ``from_dict``) for the session file.
"""
from __future__ import annotations

from dataclasses import dataclass, field
import numpy as np

from volviz.model.json_types import JSONValue

__all__ = ["BoxCrop", "ClipPlane", "ClipSettings"]


def _vec3(v: object, what: str) -> tuple[float, float, float]:
    a = np.asarray(v, dtype=np.float64).reshape(-1)
    if a.shape != (3,) or not np.all(np.isfinite(a)):
        raise ValueError(f"{what} must be 3 finite numbers, got {v!r}")
    return (float(a[0]), float(a[1]), float(a[2]))


@dataclass(frozen=True)
class ClipPlane:
    """Keeps ``(x − point)·normal ≥ 0``; the normal is stored unit length."""

    point: tuple[float, float, float]
    normal: tuple[float, float, float]

    def __post_init__(self) -> None:
        p, n = _vec3(self.point, "clip plane point"), np.asarray(_vec3(self.normal, "clip plane normal"))
        length = float(np.linalg.norm(n))
        if length < 1e-12:
            raise ValueError("clip plane normal must not be zero")
        object.__setattr__(self, "point", p)
        if abs(length - 1.0) > 1e-12:  # unit normals stay bit-identical (JSON round trips compare equal)
            n = n / length
        object.__setattr__(self, "normal", tuple(float(v) for v in n))

    def distance(self, points: np.ndarray) -> np.ndarray:
        return (np.asarray(points, dtype=np.float64) - np.asarray(self.point)) @ np.asarray(self.normal)

    def to_dict(self) -> dict[str, object]:
        return {"point": list(self.point), "normal": list(self.normal)}

    @classmethod
    def from_dict(cls, d: JSONValue) -> "ClipPlane":
        if not isinstance(d, dict) or set(d) != {"point", "normal"}:
            raise ValueError(f"clip plane must be an object with 'point' and 'normal', got {d!r}")
        return cls(_vec3(d["point"], "clip plane point"), _vec3(d["normal"], "clip plane normal"))


@dataclass(frozen=True)
class BoxCrop:
    """Keeps ``lo ≤ x ≤ hi`` (axis-aligned, world coordinates)."""

    lo: tuple[float, float, float]
    hi: tuple[float, float, float]

    def __post_init__(self) -> None:
        lo, hi = _vec3(self.lo, "box lo"), _vec3(self.hi, "box hi")
        if any(a > b for a, b in zip(lo, hi)):
            raise ValueError(f"box crop needs lo <= hi on every axis, got lo={lo} hi={hi}")
        object.__setattr__(self, "lo", lo)
        object.__setattr__(self, "hi", hi)

    def planes(self) -> list[ClipPlane]:
        out = []
        for k in range(3):
            e = [0.0, 0.0, 0.0]
            e[k] = 1.0
            out.append(ClipPlane(self.lo, (e[0], e[1], e[2])))
            e[k] = -1.0
            out.append(ClipPlane(self.hi, (e[0], e[1], e[2])))
        return out

    def to_dict(self) -> dict[str, object]:
        return {"lo": list(self.lo), "hi": list(self.hi)}

    @classmethod
    def from_dict(cls, d: JSONValue) -> "BoxCrop":
        if not isinstance(d, dict) or set(d) != {"lo", "hi"}:
            raise ValueError(f"box crop must be an object with 'lo' and 'hi', got {d!r}")
        return cls(_vec3(d["lo"], "box lo"), _vec3(d["hi"], "box hi"))


@dataclass(frozen=True)
class ClipSettings:
    """Any number of planes plus an optional box; empty settings clip nothing."""

    planes: tuple[ClipPlane, ...] = field(default_factory=tuple)
    box: BoxCrop | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "planes", tuple(self.planes))

    def all_planes(self) -> list[ClipPlane]:
        return list(self.planes) + (self.box.planes() if self.box is not None else [])

    def inside(self, points: np.ndarray, tol: float = 0.0) -> np.ndarray:
        pts = np.asarray(points, dtype=np.float64)
        keep = np.ones(pts.shape[:-1], bool)
        for p in self.all_planes():
            keep &= p.distance(pts) >= -tol
        return keep

    def to_dict(self) -> dict[str, object]:
        return {"planes": [p.to_dict() for p in self.planes], "box": None if self.box is None else self.box.to_dict()}

    @classmethod
    def from_dict(cls, d: JSONValue) -> "ClipSettings":
        if not isinstance(d, dict) or not set(d) <= {"planes", "box"}:
            raise ValueError(f"clip settings must be an object with 'planes' and 'box', got {d!r}")
        planes = d.get("planes", [])
        if not isinstance(planes, list):
            raise ValueError("clip settings 'planes' must be a list")
        box = d.get("box")
        return cls(tuple(ClipPlane.from_dict(p) for p in planes), None if box is None else BoxCrop.from_dict(box))
