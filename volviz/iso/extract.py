"""Isosurface extraction for several iso-values from several (possibly overlapping) volumes (libMini note §4).

Regular volumes go through ``vtkFlyingEdges3D``; curvilinear grids, tetrahedral and other unstructured meshes through
``vtkContourFilter``. Every iso-value carries its own color and opacity (an ``IsoStyle``); the result is one
``IsoMesh`` per (volume, iso-value): points, triangles, unit normals and the style. Normals are oriented along the
negative scalar gradient (they point out of a blob of high values), the convention the compositor uses to tell front
from back faces (4-pass mode, libMini note §4 step 3).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable, Sequence, cast

import numpy as np

from volviz.model.datasets import CurvilinearGrid, RegularVolume, TetMesh, UnstructuredMesh

__all__ = ["IsoStyle", "IsoMesh", "extract", "extract_many", "merge_meshes"]


@dataclass(frozen=True)
class IsoStyle:
    """Iso-value with color (RGB in 0..1) and opacity in [0, 1] (1 = opaque, rendered in the opaque pass)."""

    value: float
    color: tuple[float, float, float] = (1.0, 1.0, 1.0)
    opacity: float = 0.5

    def __post_init__(self) -> None:
        if not np.isfinite(self.value):
            raise ValueError(f"iso-value must be finite, got {self.value}")
        if not 0.0 <= float(self.opacity) <= 1.0:
            raise ValueError(f"iso-surface opacity must be in [0, 1], got {self.opacity}")
        c = np.asarray(self.color, dtype=np.float64)
        if c.shape != (3,) or not np.all(np.isfinite(c)) or c.min() < 0.0 or c.max() > 1.0:
            raise ValueError(f"iso-surface color must be 3 values in [0, 1], got {self.color}")

    @property
    def opaque(self) -> bool:
        return float(self.opacity) >= 1.0

    def to_dict(self) -> dict[str, Any]:
        return {"value": float(self.value), "color": [float(v) for v in self.color], "opacity": float(self.opacity)}

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> "IsoStyle":
        color = cast("tuple[float, float, float]", tuple(float(v) for v in d.get("color", (1, 1, 1))))  # checked below
        return cls(float(d["value"]), color, float(d.get("opacity", 0.5)))


@dataclass
class IsoMesh:
    """A triangle mesh: points (n,3) f64, triangles (m,3) i64, unit normals (n,3) f64, its style and origin label."""

    points: np.ndarray
    triangles: np.ndarray
    normals: np.ndarray
    style: IsoStyle
    label: str = ""
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def n_triangles(self) -> int:
        return int(self.triangles.shape[0])

    def to_pyvista(self) -> Any:
        """The mesh as a pyvista.PolyData with its normals. Built from the triangles as they are (VTK's offsets and
        connectivity, ``from_regular_faces``): 4x faster than a legacy padded face list, and it runs on the GUI
        thread each time a time series' surfaces are shown (issue #28)."""
        # PyVista (VTK): only where a surface is shown
        import pyvista as pv
        points = self.points.copy()
        poly = pv.PolyData.from_regular_faces(points, self.triangles) if self.n_triangles else pv.PolyData(points)
        poly.point_data["Normals"] = self.normals
        return poly


def _vtk_input(volume: Any, scalars: str | None) -> tuple[Any, bool]:
    """A VTK dataset with the active point scalars set; True for image data (FlyingEdges applies)."""
    if isinstance(volume, RegularVolume):
        image = volume.to_pyvista()
        first = image.point_data.keys()[0]
        image.point_data[first] = np.asarray(image.point_data[first], dtype=np.float32)
        image.set_active_scalars(first)
        return image, True
    if isinstance(volume, (CurvilinearGrid, UnstructuredMesh, TetMesh)):
        grid = volume.to_pyvista()
        name = scalars or getattr(volume, "active", None) or getattr(volume, "name", None)
        if name is None or name not in grid.point_data:
            keys = list(grid.point_data.keys())
            if not keys:
                raise ValueError(f"{type(volume).__name__} has no point scalars to contour")
            name = keys[0]
        grid.set_active_scalars(name)
        return grid, False
    raise TypeError(f"cannot extract isosurfaces from {type(volume).__name__}")


def _poly_to_arrays(poly: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    # PyVista and VTK's filters: only where surfaces are extracted
    import pyvista as pv
    from vtkmodules.vtkFiltersCore import vtkCleanPolyData, vtkTriangleFilter
    clean = vtkCleanPolyData()  # merge coincident points (degenerate grid cells), degenerate triangles -> lines
    clean.SetInputData(poly)
    clean.ToleranceIsAbsoluteOn()
    clean.SetAbsoluteTolerance(0.0)
    clean.Update()
    tri = vtkTriangleFilter()
    tri.SetInputData(clean.GetOutput())
    tri.PassLinesOff()
    tri.PassVertsOff()
    tri.Update()
    out = pv.wrap(tri.GetOutput())
    pts = np.asarray(out.points, dtype=np.float64).reshape(-1, 3)
    faces = np.asarray(out.faces, dtype=np.int64)
    tris = faces.reshape(-1, 4)[:, 1:].copy() if faces.size else np.zeros((0, 3), np.int64)
    ok = (tris[:, 0] != tris[:, 1]) & (tris[:, 1] != tris[:, 2]) & (tris[:, 0] != tris[:, 2])
    tris = tris[ok]
    normals = out.point_data.get("Normals")
    nrm = np.zeros_like(pts) if normals is None else np.asarray(normals, dtype=np.float64).reshape(-1, 3)
    return pts, tris, nrm


def _orient_normals(pts: np.ndarray, tris: np.ndarray, nrm: np.ndarray, grad_at: Callable[[np.ndarray], np.ndarray]
                    ) -> np.ndarray:
    """Unit normals along −∇s; falls back to area-weighted face normals where VTK gave none."""
    n = nrm.copy()
    bad = np.linalg.norm(n, axis=1) < 1e-12
    if bad.any() and tris.size:
        a, b, c = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
        fn = np.cross(b - a, c - a)
        acc = np.zeros_like(pts)
        for k in range(3):
            np.add.at(acc, tris[:, k], fn)
        n[bad] = acc[bad]
    length = np.linalg.norm(n, axis=1, keepdims=True)
    n = np.where(length > 1e-12, n / np.maximum(length, 1e-300), np.array([0.0, 0.0, 1.0]))
    if len(pts):
        g = grad_at(pts)
        s = np.einsum("ij,ij->i", n, g)
        if np.sum(s) > 0.0:  # majority points up the gradient: flip all (VTK is consistent within one surface)
            n = -n
    return n


def _gradient_sampler(grid: Any) -> Callable[[np.ndarray], np.ndarray]:
    """∇s at arbitrary points, by probing VTK's point gradients (vtkGradientFilter + vtkProbeFilter)."""
    def grad_at(points: np.ndarray) -> np.ndarray:
        # PyVista (VTK): only where gradients are probed
        import pyvista as pv
        idx = np.linspace(0, len(points) - 1, min(len(points), 64)).astype(np.int64)
        g = grid.compute_derivative(scalars=grid.active_scalars_name, gradient="grad")
        probe = pv.PolyData(points[idx]).sample(g)
        out = np.zeros_like(points)
        out[idx] = np.asarray(probe.point_data["grad"], dtype=np.float64)
        return out
    return grad_at


def extract(volume: Any, styles: Sequence[IsoStyle | float], scalars: str | None = None, label: str = "",
            progress: Callable[[float, str], None] | None = None) -> list[IsoMesh]:
    """One ``IsoMesh`` per style from one volume (RegularVolume, CurvilinearGrid, TetMesh, UnstructuredMesh).

    Plain numbers are accepted as styles (white, opacity 0.5). Empty surfaces (value outside the data range) are
    returned as meshes with no triangles, so the list always matches ``styles``.
    """
    # VTK's contour filters: only where surfaces are extracted
    from vtkmodules.vtkFiltersCore import vtkContourFilter, vtkFlyingEdges3D, vtkPolyDataNormals
    sty = [s if isinstance(s, IsoStyle) else IsoStyle(float(s)) for s in styles]
    grid, is_image = _vtk_input(volume, scalars)
    grad_at = _gradient_sampler(grid)
    out: list[IsoMesh] = []
    for k, st in enumerate(sty):
        if progress is not None:
            progress(k / max(len(sty), 1), f"iso-value {st.value:g}")
        f = vtkFlyingEdges3D() if is_image else vtkContourFilter()
        f.SetInputData(grid)
        f.SetValue(0, float(st.value))
        f.SetComputeNormals(True) if is_image else f.ComputeNormalsOff()
        if is_image:
            f.ComputeGradientsOff()
        f.Update()
        poly = f.GetOutput()
        if not is_image and poly.GetNumberOfCells():
            nf = vtkPolyDataNormals()
            nf.SetInputData(poly)
            nf.SplittingOff()
            nf.ConsistencyOn()
            nf.AutoOrientNormalsOff()
            nf.Update()
            poly = nf.GetOutput()
        pts, tris, nrm = _poly_to_arrays(poly)
        nrm = _orient_normals(pts, tris, nrm, grad_at) if len(pts) else nrm
        out.append(IsoMesh(pts, tris, nrm, st, label or getattr(volume, "source", "")))
    if progress is not None:
        progress(1.0, "extracted")
    return out


def extract_many(volumes: Sequence[tuple[Any, Sequence[IsoStyle | float]]], scalars: str | None = None,
                 progress: Callable[[float, str], None] | None = None) -> list[IsoMesh]:
    """All surfaces of several volumes (they may overlap in space); compositing pools them per pass (note §4)."""
    meshes: list[IsoMesh] = []
    for i, (vol, styles) in enumerate(volumes):
        if progress is not None:
            progress(i / max(len(volumes), 1), f"volume {i + 1}/{len(volumes)}")
        meshes.extend(extract(vol, styles, scalars=scalars, label=f"volume{i}"))
    return meshes


def merge_meshes(meshes: Sequence[IsoMesh]) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Concatenate: points, triangles (re-indexed), normals, per-triangle surface index into ``meshes``."""
    pts, tris, nrm, sid = [], [], [], []
    base = 0
    for i, m in enumerate(meshes):
        pts.append(m.points)
        nrm.append(m.normals)
        tris.append(m.triangles + base)
        sid.append(np.full(m.n_triangles, i, np.int64))
        base += len(m.points)
    if not meshes:
        z = np.zeros((0, 3))
        return z, np.zeros((0, 3), np.int64), z.copy(), np.zeros(0, np.int64)
    return np.concatenate(pts), np.concatenate(tris), np.concatenate(nrm), np.concatenate(sid)
