"""The probe in a viewport: the ray through a pixel, and what is under it: the nearest of the first visible samples
of the shown volumes (a regular volume or a time series' frame at the display time: ``volviz.model.probe``; a
compressed multiresolution volume at full resolution: ``volviz.regular.probe_lod``; the tetrahedral mesh a
projected-tetrahedra view draws, interpolated in its cell: ``volviz.unstructured.probe``) and the cell of a surface
VTK's cell picker hits, with its nearest point's value."""
from __future__ import annotations

import weakref
from typing import TYPE_CHECKING, Any, Optional

import numpy as np

from volviz.model import CurvilinearGrid, RegularVolume, TetMesh, TimeSeries, UnstructuredMesh
from volviz.model.probe import ProbeResult, probe_regular
from volviz.model.representation import representation
from volviz.model.timeseries import frame_at
from volviz.render.pt_view import is_pt_view
from volviz.scene.drawn_tf import drawn_tf

if TYPE_CHECKING:   # type-only: the scene's controller and components; VTK's renderer, reached through the facade
    from volviz.render.controller import SceneController
    from volviz.render.vtk_facade import vtkRenderer
    from volviz.session import Component

# id(dataset) -> (weak reference to it, its tetrahedra): the datasets are dataclasses compared by value, so no weak
# dictionary can key them; an entry leaves with its dataset
_TETS: dict[int, tuple[weakref.ref[Any], Any]] = {}


def pick_ray(renderer: vtkRenderer, x: float, y: float) -> tuple[np.ndarray, np.ndarray]:
    """The world-space ray (origin on the near plane, unit direction) through display pixel (x, y) of ``renderer``
    (VTK's display coordinates: y up from the bottom)."""
    ends = []
    for depth in (0.0, 1.0):
        renderer.SetDisplayPoint(float(x), float(y), depth)
        renderer.DisplayToWorld()
        w = np.asarray(renderer.GetWorldPoint(), dtype=np.float64)
        ends.append(w[:3] / w[3])
    direction = ends[1] - ends[0]
    return ends[0], direction / np.linalg.norm(direction)


def probe_scene(controller: SceneController, x: float, y: float) -> Optional[ProbeResult]:
    """What is under display pixel (x, y) of ``controller``'s viewport: the nearest hit among the visible volumes
    (``probe_volume``, each with its drawn transfer function) and the meshes VTK can pick."""
    origin, direction = pick_ray(controller.plotter.renderer, x, y)
    hits: list[tuple[float, ProbeResult]] = []
    for comp in controller.session.components:
        if not comp.visible or comp.type != "volume" or comp.dataset not in controller.datasets:
            continue
        hit = probe_volume(controller, comp, origin, direction)
        if hit is not None:
            hits.append((float(np.dot(np.asarray(hit.position) - origin, direction)), hit))
    picked = _pick_cell(controller.plotter.renderer, x, y)
    if picked is not None:
        hits.append((float(np.dot(np.asarray(picked.position) - origin, direction)), picked))
    return min(hits, key=lambda h: h[0])[1] if hits else None


def probe_volume(controller: SceneController, comp: Component, origin: np.ndarray,
                 direction: np.ndarray) -> Optional[ProbeResult]:
    """The first visible sample of volume component ``comp`` along the ray, by what its view draws: the mesh of a
    projected-tetrahedra view, a LOD tree, a regular volume, or the frame of a time series at the controller's
    display time (a regular volume, or a mesh through its tetrahedra), each in the part the scene's clipping keeps;
    None for what none of these draws."""
    # heavy: the LOD tree's Numba kernels and SciPy, loaded only when a point is probed
    from volviz.regular.lod import LodTree

    dataset = controller.dataset_of(comp.id)
    tf = drawn_tf(comp, controller.transfer_function(comp.id), dataset)
    view = getattr(controller.views.get(comp.id), "prop", None)
    if is_pt_view(view):
        if not view.visible:
            return None
        # heavy: the probe's Numba kernels and SciPy, loaded only when a mesh is probed
        from volviz.unstructured.probe import probe_tetmesh

        return probe_tetmesh(view.mesh, origin, direction, tf, comp.id, comp.opacity, controller.clip)
    if isinstance(dataset, LodTree):
        # heavy: the LOD probe's Numba kernels and SciPy, loaded only when a LOD volume is probed
        from volviz.regular.probe_lod import probe_lod

        return probe_lod(dataset, origin, direction, tf, comp.id, comp.opacity, controller.clip)
    if isinstance(dataset, TimeSeries):
        dataset = frame_at(dataset, controller.time, controller.interpolate_time)
    if isinstance(dataset, RegularVolume):
        return probe_regular(dataset, origin, direction, tf, comp.id, comp.opacity, controller.clip)
    mesh = _volume_tets(dataset)
    if mesh is not None:        # a mesh VTK's volume mapper draws (a time series, the "vtk" render method)
        # heavy: the probe's Numba kernels and SciPy, loaded only when a mesh is probed
        from volviz.unstructured.probe import probe_tetmesh

        return probe_tetmesh(mesh, origin, direction, tf, comp.id, comp.opacity, controller.clip)
    return None


def _volume_tets(dataset: Any) -> Optional[Any]:
    """The tetrahedral mesh of a volumetric mesh dataset (made once and kept while it lives), None for anything else
    (a surface: VTK's cell picker answers for it)."""
    if not isinstance(dataset, (TetMesh, UnstructuredMesh, CurvilinearGrid)) or \
            representation(dataset).kind != "volume":
        return None
    if isinstance(dataset, TetMesh):
        return dataset
    kept = _TETS.get(id(dataset))
    if kept is None or kept[0]() is not dataset:
        # heavy: the tetrahedralisation's Numba kernels and SciPy, only when a grid is probed
        from volviz.unstructured.tetrahedralize import tetrahedralize

        tets = tetrahedralize(dataset, dataset.active)
        kept = _TETS[id(dataset)] = (weakref.ref(dataset, _forget_tets(id(dataset))), tets)
    return kept[1]


def _forget_tets(key: int) -> Any:
    """The callback that drops ``_TETS[key]`` when its dataset is collected (not a later dataset's at that id)."""
    def forget(ref: weakref.ref[Any]) -> None:
        if key in _TETS and _TETS[key][0] is ref:
            del _TETS[key]
    return forget


def _pick_cell(renderer: Any, x: float, y: float) -> Optional[ProbeResult]:
    """The cell of a pickable surface or mesh actor under the pixel, with the value of its active point scalars at
    the cell's point nearest the hit (None: nothing, or no scalars)."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    picker = vtk.vtkCellPicker()
    picker.SetTolerance(0.0005)
    picker.PickFromListOff()
    if not picker.Pick(float(x), float(y), 0.0, renderer) or picker.GetCellId() < 0 or picker.GetActor() is None:
        return None
    data = picker.GetDataSet()
    scalars = data.GetPointData().GetScalars() if data is not None else None
    point = int(picker.GetPointId())
    if scalars is None or point < 0:
        return None
    name = scalars.GetName() or "mesh"
    position = tuple(float(v) for v in picker.GetPickPosition())
    return ProbeResult(str(name), float(scalars.GetComponent(point, 0)), position,  # type: ignore[arg-type]
                       cell=int(picker.GetCellId()), point=point)
