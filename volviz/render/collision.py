"""Where a moving eye meets opaque geometry: fly mode stops short of it (``FlyNavigator.obstacle``).

The obstacles are the visible opaque surfaces of a VTK renderer (opacity 1: isosurfaces, meshes, whatever the user
added), found with VTK's cell locator; volviz's image overlays, the natural scene (its terrain is kept below the eye
by its height function instead) and the decorations are not obstacles. The locator is rebuilt only when those
surfaces change."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Mapping, Optional, Sequence

import numpy as np

if TYPE_CHECKING:   # type-only: the natural scene's terrain
    from volviz.nature.heightfield import HeightField

NOT_OBSTACLES = ("nature-terrain", "nature-sky", "volviz-outline")
DEFAULT_CLEARANCE = 0.01      # of the scene's size


def fly_clearance(options: Mapping[str, object]) -> float:
    """The fly-mode clearance as a share of the scene's size: the render option ``fly_clearance`` (0 to 0.5), else
    ``DEFAULT_CLEARANCE``."""
    value = options.get("fly_clearance", DEFAULT_CLEARANCE)
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not 0.0 <= float(value) <= 0.5:
        return DEFAULT_CLEARANCE
    return float(value)


def fly_bounds(scene_bounds: Sequence[float], eye: Sequence[float],
               terrain: Optional[HeightField] = None) -> tuple[float, ...]:
    """The box a flying eye stays in: around a terrain, half its extent beyond each side and up to its extent above
    its highest point (the sky dome's bounds are 6 times wider); else the scene's bounds grown by their size on
    every side. The box holds the ``eye`` where the flight starts, so the first step never jumps."""
    if terrain is not None:
        x0, y0 = (float(v) for v in terrain.origin[:2])
        ex, ey = (float(v) for v in terrain.extent[:2])
        box = [x0 - ex / 2, x0 + 1.5 * ex, y0 - ey / 2, y0 + 1.5 * ey, float(np.min(terrain.heights)),
               float(np.max(terrain.heights)) + max(ex, ey)]
    else:
        b = np.asarray(scene_bounds, dtype=np.float64)
        size = max(float(np.max(b[1::2] - b[0::2])), 1e-9)
        box = [b[0] - size, b[1] + size, b[2] - size, b[3] + size, b[4] - size, b[5] + size]
    for axis, value in enumerate(float(v) for v in eye):
        box[2 * axis] = min(box[2 * axis], value)
        box[2 * axis + 1] = max(box[2 * axis + 1], value)
    return tuple(float(v) for v in box)


class OpaqueObstacles:
    """``obstacles(start, end)``: the distance from ``start`` to the first opaque surface on the segment, or None."""

    def __init__(self, renderer: Any) -> None:
        self.renderer = renderer
        self._key: Optional[tuple] = None
        self._locator: Any = None

    def _surfaces(self) -> list[Any]:
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        names = {id(a) for name, a in getattr(self.renderer, "actors", {}).items() if name in NOT_OBSTACLES}
        out = []
        actors = self.renderer.GetActors()
        actors.InitTraversal()
        for _ in range(actors.GetNumberOfItems()):
            actor = actors.GetNextActor()
            if id(actor) in names or not actor.GetVisibility() or actor.GetProperty().GetOpacity() < 1.0:
                continue
            data = actor.GetMapper().GetInput() if actor.GetMapper() is not None else None
            if data is None or not data.IsA("vtkPolyData") or data.GetNumberOfPolys() + data.GetNumberOfStrips() == 0:
                continue
            if not _identity(actor.GetMatrix()):
                transform = vtk.vtkTransformPolyDataFilter()
                transform.SetInputData(data)
                matrix = vtk.vtkTransform()
                matrix.SetMatrix(actor.GetMatrix())
                transform.SetTransform(matrix)
                transform.Update()
                data = transform.GetOutput()
            out.append((actor, data))
        return out

    def _build(self) -> Any:
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        surfaces = self._surfaces()
        key = tuple((id(a), a.GetMTime(), d.GetMTime()) for a, d in surfaces)
        if key != self._key:
            self._key, self._locator = key, None
            if surfaces:
                append = vtk.vtkAppendPolyData()
                for _, data in surfaces:
                    append.AddInputData(data)
                append.Update()
                locator = vtk.vtkCellLocator()
                locator.SetDataSet(append.GetOutput())
                locator.BuildLocator()
                self._locator = (locator, append.GetOutput())
        return self._locator

    def __call__(self, start: np.ndarray, end: np.ndarray) -> Optional[float]:
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk_to_numpy, vtk

        built = self._build()
        if built is None:
            return None
        locator, _ = built
        points, cells = vtk.vtkPoints(), vtk.vtkIdList()
        p0, p1 = [float(v) for v in start], [float(v) for v in end]
        locator.IntersectWithLine(p0, p1, 1e-9, points, cells)   # every crossing (a tolerance keeps those through
        # a vertex or an edge, which an exact test can miss): the nearest one counts
        if points.GetNumberOfPoints() == 0:
            return None
        return float(np.linalg.norm(vtk_to_numpy(points.GetData()) - np.asarray(p0), axis=1).min())


def _identity(matrix: Any) -> bool:
    return all(matrix.GetElement(i, j) == (1.0 if i == j else 0.0) for i in range(4) for j in range(4))
