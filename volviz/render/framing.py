"""Framing the camera on what a scene shows: the bounds of every visible component, volviz's own views included
(PT volumes and the natural scene draw image overlays, which VTK's ResetCamera does not see), and a camera that makes
those bounds fill a given share of the viewport."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Mapping, Optional

import numpy as np

from volviz.model.extent import point_extent
from volviz.scene.lod import lod_bounds

if TYPE_CHECKING:   # type-only imports for the signatures
    import numpy.typing as npt
    import pyvista as pv

    from volviz.nature.nature_scene import NatureScene

Bounds = tuple[float, float, float, float, float, float]

FILL = 0.8                                    # share of the viewport's limiting dimension the data fills
ISOMETRIC = (1.0, 1.0, 1.0)                   # from the focal point towards the camera, as VTK's isometric view


def _valid(bounds: Any) -> bool:
    b = np.asarray(bounds, dtype=np.float64)
    return b.shape == (6,) and bool(np.all(np.isfinite(b))) and bool(np.all(b[1::2] >= b[0::2]))


def nature_bounds(scene: NatureScene) -> Optional[Bounds]:
    """The bounds of a NatureScene: its terrain and the clouds above it (not the sky dome around the eye)."""
    parts: list[tuple[float, ...]] = []
    if scene.terrain is not None:
        parts.append(scene.terrain.bounds())
    if scene.cloud_lod is not None:
        parts.append(scene.cloud_lod.volume.bounds())
    return union([tuple(float(v) for v in b) for b in parts if _valid(b)])  # type: ignore[misc]


def prop_bounds(prop: object) -> Optional[Bounds]:
    """The world bounds of one component's prop: a NatureView (its terrain, else its clouds), a PT volume (its
    mesh), a LOD volume (its samples), a VTK prop (what VTK reports); None when empty or a hidden VTK prop (callers
    leave out the props of hidden components)."""
    scene = getattr(prop, "scene", None)
    if scene is not None and hasattr(prop, "terrain_actor"):
        return nature_bounds(scene)
    mesh = getattr(prop, "mesh", None)
    if mesh is not None and hasattr(mesh, "points"):   # (an overlay is hidden until its first image: not checked)
        return points_bounds(mesh.points) if len(mesh.points) else None
    tree = getattr(prop, "tree", None)
    if tree is not None:
        return lod_bounds(tree)
    if hasattr(prop, "GetBounds"):
        if hasattr(prop, "GetVisibility") and not prop.GetVisibility():
            return None
        b = prop.GetBounds()
        return tuple(float(v) for v in b) if b is not None and _valid(b) else None  # type: ignore[return-value]
    return None


def union(boxes: list[Bounds]) -> Optional[Bounds]:
    """The smallest box holding every box of ``boxes`` (None for none)."""
    if not boxes:
        return None
    arr = np.asarray(boxes, dtype=np.float64)
    return tuple(float(v) for v in np.ravel(np.column_stack([arr[:, 0::2].min(axis=0),  # type: ignore[return-value]
                                                              arr[:, 1::2].max(axis=0)])))


def points_bounds(points: np.ndarray) -> Bounds:
    lo, hi = point_extent(points)
    return (float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1]), float(lo[2]), float(hi[2]))


def scene_bounds(props: Mapping[str, object]) -> Optional[Bounds]:
    """The union of the bounds of every component prop (None when nothing has bounds)."""
    return union([b for b in (prop_bounds(p) for p in props.values()) if b is not None])


def framing_distance(bounds: Bounds, direction: npt.ArrayLike, view_up: npt.ArrayLike, view_angle: float, aspect: float,
                     fill: float = FILL) -> tuple[np.ndarray, float]:
    """(focal point, distance) of a perspective camera looking along ``-direction`` at the box's centre from which
    every corner of the box projects inside ``fill`` of the viewport (exactly at ``fill`` in the limiting
    dimension)."""
    lo, hi = np.asarray(bounds[0::2], float), np.asarray(bounds[1::2], float)
    centre = 0.5 * (lo + hi)
    d = np.asarray(direction, float)
    d = d / np.linalg.norm(d)
    right = np.cross(np.asarray(view_up, float), d)
    right = right / np.linalg.norm(right)
    up = np.cross(d, right)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]) - centre
    tan_v = np.tan(np.radians(view_angle) / 2.0) * fill
    tan_h = tan_v * aspect
    need = np.maximum(np.abs(corners @ right) / tan_h, np.abs(corners @ up) / tan_v) + corners @ d
    distance = float(need.max())
    extent = float(np.linalg.norm(hi - lo))
    return centre, max(distance, 1e-3 * extent, 1e-9)


def view_direction(bounds: Bounds) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """(direction towards the camera, view up) for a box: face-on for flat data (an image, a 2D grid: seen along its
    thin axis), else the isometric view with z up."""
    sides = np.subtract(bounds[1::2], bounds[0::2])
    thin = int(np.argmin(sides))
    if sides[thin] <= 1e-9 * max(float(np.max(sides)), 1e-300):
        return ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)) if thin == 2 else \
               (((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)) if thin == 0 else ((0.0, -1.0, 0.0), (0.0, 0.0, 1.0)))
    return ISOMETRIC, (0.0, 0.0, 1.0)


def frame_bounds(plotter: pv.BasePlotter, bounds: Optional[Bounds], fill: float = FILL,
                 right_margin: float = 0.0) -> None:
    """Point the plotter's camera at ``bounds`` (from ``view_direction``) so they fill ``fill`` of the viewport
    left of a ``right_margin`` share of its width (kept for the scalar bar); with no bounds, VTK's own reset."""
    camera = plotter.renderer.GetActiveCamera()
    if bounds is None:
        plotter.view_isometric(render=False)  # type: ignore[call-arg]  # pyvista's _Wrapped decorator hides self from mypy
        plotter.renderer.reset_camera(render=False)   # (the plotter's own reset_camera renders in any case)
        return
    width, height = plotter.window_size
    aspect = width / max(height, 1)
    view, up = view_direction(bounds)
    centre, distance = framing_distance(bounds, view, up, camera.GetViewAngle(), aspect * (1.0 - right_margin), fill)
    direction = np.asarray(view) / np.linalg.norm(view)
    right = np.cross(np.asarray(up, float), direction)
    right /= np.linalg.norm(right)
    # the data's centre moves left of the window's centre by half the margin: the camera moves right by that much
    shift = right_margin * distance * np.tan(np.radians(camera.GetViewAngle()) / 2.0) * aspect
    camera.SetFocalPoint(*(centre + shift * right))
    camera.SetPosition(*(centre + shift * right + distance * direction))
    camera.SetViewUp(*up)
    if camera.GetParallelProjection():
        lo, hi = np.asarray(bounds[0::2]), np.asarray(bounds[1::2])
        camera.SetParallelScale(0.5 * float(np.linalg.norm(hi - lo)) / fill)
    renderer = plotter.renderer
    renderer.ResetCameraClippingRange()               # what VTK draws (the sky dome included) ...
    near, far = camera.GetClippingRange()
    renderer.ResetCameraClippingRange(*bounds)        # ... and volviz's own views
    camera.SetClippingRange(min(near, camera.GetClippingRange()[0]), max(far, camera.GetClippingRange()[1]))
    plotter.camera_set = True          # else PyVista re-frames its own props at the next render


def frame_scene(plotter: pv.BasePlotter, props: Mapping[str, object], fill: float = FILL, right_margin: float = 0.0
                ) -> None:
    """Frame every visible component of a scene (``scene_bounds``)."""
    frame_bounds(plotter, scene_bounds(props), fill, right_margin)
