"""The probe in a viewport: the ray through a pixel, and what is under it (``volviz.model.probe``): the first
visible sample of a regular volume, else the cell of a mesh VTK's cell picker hits, with its nearest point's value."""
from __future__ import annotations

from typing import Any, Optional

import numpy as np

from volviz.model.probe import ProbeResult, probe_regular


def pick_ray(renderer: Any, x: float, y: float) -> tuple[np.ndarray, np.ndarray]:
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


def probe_scene(controller: Any, x: float, y: float) -> Optional[ProbeResult]:
    """What is under display pixel (x, y) of ``controller``'s viewport: the nearest hit among the visible regular
    volumes (drawn transfer function, ``probe_regular``) and the meshes VTK can pick."""
    from volviz.model import RegularVolume
    from volviz.scene.drawn_tf import drawn_tf

    origin, direction = pick_ray(controller.plotter.renderer, x, y)
    hits: list[tuple[float, ProbeResult]] = []
    for comp in controller.session.components:
        if not comp.visible or comp.type != "volume" or comp.dataset not in controller.datasets:
            continue
        dataset = controller.dataset_of(comp.id)
        if isinstance(dataset, RegularVolume):
            tf = drawn_tf(comp, controller.transfer_function(comp.id), dataset)
            hit = probe_regular(dataset, origin, direction, tf, comp.id, comp.opacity)
            if hit is not None:
                hits.append((float(np.dot(np.asarray(hit.position) - origin, direction)), hit))
    picked = _pick_cell(controller.plotter.renderer, x, y)
    if picked is not None:
        hits.append((float(np.dot(np.asarray(picked.position) - origin, direction)), picked))
    return min(hits, key=lambda h: h[0])[1] if hits else None


def _pick_cell(renderer: Any, x: float, y: float) -> Optional[ProbeResult]:
    """The cell of a pickable surface or mesh actor under the pixel, with the value of its active point scalars at
    the cell's point nearest the hit (None: nothing, or no scalars)."""
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
