"""Clipping planes and a box crop (libMini note, Fig. 6; the settings are ``volviz.model.clip``'s) applied alike to
regular volumes, isosurfaces and tetrahedral meshes. A plane ``(point, normal)`` keeps the half-space
``(x − point)·normal ≥ 0``; several planes keep their intersection; the box keeps ``lo ≤ x ≤ hi``.

- Isosurfaces and tetrahedral meshes are cut exactly (VTK's vtkClipPolyData / vtkTableBasedClipDataSet per plane):
  new points lie on the plane, their normals / scalars are linearly interpolated along the cut edges, which for a
  tetrahedral mesh reproduces the linear field exactly.
- Regular volumes: the box crop is the sub-grid of the samples inside the box (exact, no resampling); clipping planes
  mark the samples outside as NaN, which the transfer function convention renders transparent (voxel-accurate, not
  exact: extract isosurfaces from the cropped volume and cut the surfaces with ``clip_isosurfaces`` instead).
"""
from __future__ import annotations

from dataclasses import replace
from typing import Any, Sequence

import numpy as np

from volviz.iso.extract import IsoMesh
from volviz.model.clip import BoxCrop, ClipPlane, ClipSettings
from volviz.model.datasets import RegularVolume, TetMesh, vec3

__all__ = ["clip_volume", "clip_isosurface", "clip_isosurfaces", "clip_tetmesh", "clip_grid"]


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
    # VTK's clipping filters: loaded only where something is clipped
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
    # PyVista (VTK) and extract's poly data conversion: only where a surface is clipped
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
    # VTK's tetrahedralising filter: only where a grid is clipped
    from vtkmodules.vtkFiltersGeneral import vtkDataSetTriangleFilter
    out = _clip_vtk(grid, _as_settings(clip).all_planes(), poly=False)
    tf = vtkDataSetTriangleFilter()
    tf.SetInputData(out)
    tf.TetrahedraOnlyOn()
    tf.Update()
    return tf.GetOutput()


def clip_tetmesh(mesh: TetMesh, clip: ClipSettings | Sequence[ClipPlane] | BoxCrop) -> TetMesh:
    """The tetrahedral mesh cut by the planes and box, re-tetrahedralised; scalars exact for the linear field."""
    # PyVista (VTK): only where a mesh is clipped
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
