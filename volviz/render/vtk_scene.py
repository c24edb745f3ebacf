"""Put volviz datasets into a PyVista plotter with sensible defaults (the VTK side of DESIGN.md's `render` layer).

Each dataset kind gets the visual a user expects on first open: regular volumes and unstructured meshes as volumes with
a transfer function fitted to the data range, 2D rasters as a height-field surface (or a flat image for colour),
time series as their first frame. Nothing here imports Qt: the same code renders offscreen for the CLI and inside
the app's viewport.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Optional

import numpy as np

from volviz.model import CurvilinearGrid, Image2D, RegularVolume, TetMesh, TimeSeries, UnstructuredMesh
from volviz.session import CameraState

DEFAULT_COLORS = ((0.23, 0.30, 0.75), (0.87, 0.87, 0.87), (0.71, 0.02, 0.15))  # cool-warm endpoints and middle


@dataclass
class VolumeStyle:
    """How a volume looks in VTK: colour map points (scalar, r, g, b) and opacity points (scalar, opacity per unit)."""

    colors: list[tuple[float, float, float, float]]
    opacities: list[tuple[float, float]]
    unit_distance: float = 1.0


def default_style(scalar_range: tuple[float, float], unit_distance: float) -> VolumeStyle:
    """A cool-warm colour map with a ramp opacity over the data range: the first look at unknown data."""
    lo, hi = scalar_range
    if not (np.isfinite(lo) and np.isfinite(hi)):
        lo, hi = 0.0, 1.0
    if hi <= lo:
        hi = lo + 1.0
    mid = 0.5 * (lo + hi)
    colors = [(lo, *DEFAULT_COLORS[0]), (mid, *DEFAULT_COLORS[1]), (hi, *DEFAULT_COLORS[2])]
    opacities = [(lo, 0.0), (lo + 0.1 * (hi - lo), 0.0), (hi, 0.8)]
    return VolumeStyle(colors, opacities, unit_distance)


def vtk_volume_property(style: VolumeStyle) -> Any:
    import vtk

    ctf = vtk.vtkColorTransferFunction()
    for s, r, g, b in style.colors:
        ctf.AddRGBPoint(s, r, g, b)
    otf = vtk.vtkPiecewiseFunction()
    for s, a in style.opacities:
        otf.AddPoint(s, a)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(ctf)
    prop.SetScalarOpacity(otf)
    prop.SetScalarOpacityUnitDistance(style.unit_distance)
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOff()
    return prop


def _characteristic_length(bounds: tuple[float, ...]) -> float:
    diag = float(np.linalg.norm(np.subtract(bounds[1::2], bounds[0::2])))
    return diag / 50.0 if diag > 0 else 1.0


def add_dataset(plotter: Any, dataset: Any, style: Optional[VolumeStyle] = None, opacity: float = 1.0,
                name: Optional[str] = None) -> Any:
    """Add a dataset to ``plotter`` as its default visual; returns the VTK prop."""
    import vtk

    if isinstance(dataset, TimeSeries):
        return add_dataset(plotter, dataset.frame(0), style, opacity, name)
    if isinstance(dataset, Image2D):
        return _add_image(plotter, dataset, name)

    if isinstance(dataset, (TetMesh, UnstructuredMesh, CurvilinearGrid, RegularVolume)):
        grid = dataset.to_pyvista()
    else:
        grid = dataset
    if grid.active_scalars is None:
        return plotter.add_mesh(grid, opacity=opacity, name=name)
    scalars = np.asarray(grid.active_scalars)
    if scalars.ndim > 1:  # vectors: show their magnitude
        grid.point_data["magnitude"] = np.linalg.norm(scalars, axis=1)
        grid.set_active_scalars("magnitude")
    rng = grid.get_data_range()
    style = style or default_style(rng, _characteristic_length(grid.bounds))

    if isinstance(dataset, RegularVolume):
        mapper = vtk.vtkSmartVolumeMapper()
        mapper.SetInputData(grid)
    else:
        ugrid = grid if grid.GetDataObjectType() == vtk.VTK_UNSTRUCTURED_GRID else grid.cast_to_unstructured_grid()
        tets = vtk.vtkDataSetTriangleFilter()
        tets.SetInputData(ugrid)
        tets.Update()
        mapper = vtk.vtkProjectedTetrahedraMapper()
        mapper.SetInputData(tets.GetOutput())
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    prop = vtk_volume_property(style)
    if opacity < 1.0:
        prop.SetScalarOpacityUnitDistance(style.unit_distance / max(opacity, 1e-6))
    volume.SetProperty(prop)
    plotter.add_actor(volume, name=name, reset_camera=False)
    return volume


def _add_image(plotter: Any, image: Image2D, name: Optional[str]) -> Any:
    grid = image.to_pyvista()
    if image.channels >= 3:
        colors = np.asarray(image.data[..., :3], dtype=np.float64).reshape(-1, 3)
        scale = float(image.maxval or max(colors.max(), 1.0))
        grid.point_data["rgb"] = np.clip(colors / scale * 255.0, 0, 255).astype(np.uint8)
        return plotter.add_mesh(grid, scalars="rgb", rgb=True, name=name)
    heights = np.asarray(grid.point_data["values"], dtype=np.float64)
    extent = max(image.data.shape[0] * image.spacing[1], image.data.shape[1] * image.spacing[0])
    span = float(np.nanmax(heights) - np.nanmin(heights)) or 1.0
    surface = grid.extract_surface(algorithm="dataset_surface")
    surface.point_data["height"] = heights
    factor = 0.25 * extent / span if span > 0.5 * extent else 1.0  # exaggerate only flat-looking raw grey maps
    warped = surface.warp_by_scalar("height", factor=factor)
    return plotter.add_mesh(warped, scalars="height", cmap="gist_earth", name=name, smooth_shading=True)


def apply_camera(plotter: Any, camera: Optional[CameraState]) -> None:
    """Set the plotter's camera from a session camera, or frame the scene from a pleasant oblique view."""
    if camera is None:
        plotter.view_isometric()
        plotter.reset_camera()
        return
    cam = plotter.camera
    cam.position = camera.position
    cam.focal_point = camera.focal_point
    cam.up = camera.view_up
    cam.view_angle = camera.view_angle
    cam.parallel_projection = camera.parallel
    cam.parallel_scale = camera.parallel_scale
    plotter.renderer.ResetCameraClippingRange()


def camera_state(plotter: Any) -> CameraState:
    cam = plotter.camera
    return CameraState(position=tuple(map(float, cam.position)), focal_point=tuple(map(float, cam.focal_point)),
                       view_up=tuple(map(float, cam.up)), view_angle=float(cam.view_angle),
                       parallel=bool(cam.parallel_projection), parallel_scale=float(cam.parallel_scale))
