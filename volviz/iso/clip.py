"""Clipping planes and a box crop (libMini note, Fig. 6) applied alike to regular volumes, isosurfaces and tetrahedral
meshes. A plane ``(point, normal)`` keeps the half-space ``(x − point)·normal ≥ 0``; several planes keep their
intersection; the box keeps ``lo ≤ x ≤ hi``. Settings are plain JSON (``ClipSettings.to_dict`` / ``from_dict``) for
the session file.

- Isosurfaces and tetrahedral meshes are cut exactly (VTK's vtkClipPolyData / vtkTableBasedClipDataSet per plane):
  new points lie on the plane, their normals / scalars are linearly interpolated along the cut edges, which for a
  tetrahedral mesh reproduces the linear field exactly.
- Regular volumes: the box crop is the sub-grid of the samples inside the box (exact, no resampling); clipping planes
  mark the samples outside as NaN, which the transfer function convention renders transparent (voxel-accurate, not
  exact: extract isosurfaces from the cropped volume and cut the surfaces with ``clip_isosurfaces`` instead).
"""
from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Sequence

import numpy as np

from volviz.iso.extract import IsoMesh
from volviz.model.datasets import RegularVolume, TetMesh, vec3

__all__ = ["ClipPlane", "BoxCrop", "ClipSettings", "clip_volume", "clip_isosurface", "clip_isosurfaces",
           "clip_tetmesh", "clip_grid"]


def _vec3(v: Any, what: str) -> tuple[float, float, float]:
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

    def to_dict(self) -> dict[str, Any]:
        return {"point": list(self.point), "normal": list(self.normal)}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "ClipPlane":
        if not isinstance(d, dict) or set(d) != {"point", "normal"}:
            raise ValueError(f"clip plane must be an object with 'point' and 'normal', got {d!r}")
        return cls(d["point"], d["normal"])


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

    def to_dict(self) -> dict[str, Any]:
        return {"lo": list(self.lo), "hi": list(self.hi)}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "BoxCrop":
        if not isinstance(d, dict) or set(d) != {"lo", "hi"}:
            raise ValueError(f"box crop must be an object with 'lo' and 'hi', got {d!r}")
        return cls(d["lo"], d["hi"])


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

    def to_dict(self) -> dict[str, Any]:
        return {"planes": [p.to_dict() for p in self.planes], "box": None if self.box is None else self.box.to_dict()}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "ClipSettings":
        if not isinstance(d, dict) or not set(d) <= {"planes", "box"}:
            raise ValueError(f"clip settings must be an object with 'planes' and 'box', got {d!r}")
        planes = d.get("planes", [])
        if not isinstance(planes, list):
            raise ValueError("clip settings 'planes' must be a list")
        box = d.get("box")
        return cls(tuple(ClipPlane.from_dict(p) for p in planes), None if box is None else BoxCrop.from_dict(box))


def _as_settings(clip: ClipSettings | Sequence[ClipPlane] | BoxCrop) -> ClipSettings:
    if isinstance(clip, ClipSettings):
        return clip
    if isinstance(clip, BoxCrop):
        return ClipSettings(box=clip)
    return ClipSettings(tuple(clip))


def clip_volume(volume: RegularVolume, clip: ClipSettings | Sequence[ClipPlane] | BoxCrop) -> RegularVolume:
    """Box crop = exact sub-grid of the samples inside the box; samples outside a plane become NaN (float32)."""
    cs = _as_settings(clip)
    data, origin = volume.data, np.asarray(volume.origin, dtype=np.float64)
    sp = np.asarray(volume.spacing, dtype=np.float64)
    if cs.box is not None:
        lo_i = np.maximum(np.ceil((np.asarray(cs.box.lo) - origin) / sp - 1e-9), 0).astype(int)
        hi_i = np.minimum(np.floor((np.asarray(cs.box.hi) - origin) / sp + 1e-9), np.array(data.shape) - 1).astype(int)
        if np.any(hi_i < lo_i):
            raise ValueError(f"box crop {cs.box.to_dict()} contains no sample of the volume")
        data = data[lo_i[0]:hi_i[0] + 1, lo_i[1]:hi_i[1] + 1, lo_i[2]:hi_i[2] + 1]
        origin = origin + lo_i * sp
    if cs.planes:
        axes = [origin[k] + sp[k] * np.arange(data.shape[k]) for k in range(3)]
        grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)
        keep = ClipSettings(cs.planes).inside(grid)
        data = np.where(keep, data.astype(np.float32), np.float32(np.nan))
    return replace(volume, data=np.ascontiguousarray(data), origin=vec3(origin, "origin"))


def _clip_vtk(dataset: Any, planes: list[ClipPlane], poly: bool) -> Any:
    from vtkmodules.vtkCommonDataModel import vtkPlane
    from vtkmodules.vtkFiltersCore import vtkClipPolyData
    from vtkmodules.vtkFiltersGeneral import vtkTableBasedClipDataSet
    out = dataset
    for p in planes:
        if out.GetNumberOfCells() == 0:
            break
        plane = vtkPlane()
        plane.SetOrigin(*p.point)
        plane.SetNormal(*p.normal)
        f = vtkClipPolyData() if poly else vtkTableBasedClipDataSet()
        f.SetInputData(out)
        f.SetClipFunction(plane)
        f.SetValue(0.0)
        f.InsideOutOff()  # keep where the plane function (x − p)·n ≥ 0
        f.Update()
        out = f.GetOutput()
    return out


def clip_isosurface(mesh: IsoMesh, clip: ClipSettings | Sequence[ClipPlane] | BoxCrop) -> IsoMesh:
    """The part of the surface inside all planes and the box, cut exactly (normals interpolated, renormalised)."""
    import pyvista as pv
    from volviz.iso.extract import _poly_to_arrays
    cs = _as_settings(clip)
    planes = cs.all_planes()
    if not planes or mesh.n_triangles == 0:
        return mesh
    out = pv.wrap(_clip_vtk(mesh.to_pyvista(), planes, poly=True))
    if out.n_cells == 0:
        z = np.zeros((0, 3))
        return IsoMesh(z, np.zeros((0, 3), np.int64), z.copy(), mesh.style, mesh.label, dict(mesh.extra))
    pts, tris, nrm = _poly_to_arrays(out)
    nrm = nrm / np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-300)
    return IsoMesh(pts, tris, nrm, mesh.style, mesh.label, dict(mesh.extra))


def clip_isosurfaces(meshes: Sequence[IsoMesh], clip: ClipSettings | Sequence[ClipPlane] | BoxCrop) -> list[IsoMesh]:
    return [clip_isosurface(m, clip) for m in meshes]


def clip_grid(grid: Any, clip: ClipSettings | Sequence[ClipPlane] | BoxCrop) -> Any:
    """A VTK/PyVista volumetric grid cut by the planes and box and re-tetrahedralised (a vtkUnstructuredGrid of
    tetrahedra; point data interpolated linearly along the cut edges, exact for a linear field on tetrahedra)."""
    from vtkmodules.vtkFiltersGeneral import vtkDataSetTriangleFilter
    out = _clip_vtk(grid, _as_settings(clip).all_planes(), poly=False)
    tf = vtkDataSetTriangleFilter()
    tf.SetInputData(out)
    tf.TetrahedraOnlyOn()
    tf.Update()
    return tf.GetOutput()


def clip_tetmesh(mesh: TetMesh, clip: ClipSettings | Sequence[ClipPlane] | BoxCrop) -> TetMesh:
    """The tetrahedral mesh cut by the planes and box, re-tetrahedralised; scalars exact for the linear field."""
    import pyvista as pv
    cs = _as_settings(clip)
    if not cs.all_planes():
        return mesh
    grid = mesh.to_pyvista()
    grid.set_active_scalars(grid.point_data.keys()[0])
    res = pv.wrap(clip_grid(grid, cs))
    if res.n_cells == 0:
        raise ValueError("the clipping removes the whole tetrahedral mesh")
    tets = np.asarray(res.cells, dtype=np.int64).reshape(-1, 5)[:, 1:]
    scal = np.asarray(res.point_data[grid.point_data.keys()[0]], dtype=np.float64)
    return TetMesh(np.asarray(res.points, dtype=np.float64), tets, scal, mesh.name, mesh.source)
