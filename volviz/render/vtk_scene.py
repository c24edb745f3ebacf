"""Put volviz datasets into a PyVista plotter with sensible defaults (the VTK side of the `render` layer,
docs/architecture.md).

Each dataset kind gets the visual a user expects on first open: regular volumes and unstructured meshes as volumes with
a transfer function fitted to the data range, 2D rasters as a height-field surface (or a flat image for color),
time series as their first frame. Nothing here imports Qt: the same code renders offscreen for the CLI and inside
the app's viewport.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Optional, Union

import numpy as np

from volviz.model import CurvilinearGrid, Image2D, RegularVolume, TetMesh, TimeSeries, UnstructuredMesh, vec3
from volviz.model.arrays import is_appearance_array, vertex_colors
from volviz.model.extent import point_extent
from volviz.model.representation import VOLUME, representation
from volviz.model.stats import scalar_values
from volviz.optics import TransferFunction
from volviz.optics.auto_tf import auto_transfer_function, mean_chord
from volviz.render.backend import choose_backend, plotter_gl_info
from volviz.render.vtk_tf import tf_to_vtk
from volviz.scene.lod import is_lod, lod_bounds, lod_scalar_range
from volviz.session import CameraState

if TYPE_CHECKING:   # type-only imports for the signatures
    import pyvista as pv

    from volviz.model.datasets import Dataset
    from volviz.render.vtk_facade import vtkDataObject, vtkVolume, vtkVolumeProperty
    from volviz.scene.datasets import LoadedDataset

    #: what a mapper draws: a PyVista grid, or a VTK filter's output (the tetrahedra of ``volume_input``)
    MapperInput = Union[pv.DataSet, vtkDataObject]

PLAIN_COLOR = (0.80, 0.80, 0.78)    # geometry without a field: a neutral light grey, shaded by the lights
DEFAULT_COLORS = ((0.23, 0.30, 0.75), (0.87, 0.87, 0.87), (0.71, 0.02, 0.15))  # cool-warm: low, middle, high


def default_transfer_function(scalar_range: tuple[float, float], diagonal: float,
                              name: str = "default") -> TransferFunction:
    """A cool-warm color map with a ramp extinction over the data range: the first look at unknown data.

    The extinction peaks at 8 / diagonal, so a ray through the whole bounding box at the top of the range reaches an
    optical depth of about 8 (opaque) while lower values stay translucent.
    """
    lo, hi = scalar_range
    if not (np.isfinite(lo) and np.isfinite(hi)):
        lo, hi = 0.0, 1.0
    if hi <= lo:
        hi = lo + 1.0
    rho_max = 8.0 / diagonal if diagonal > 0 else 1.0
    scalars = [lo, lo + 0.1 * (hi - lo), 0.5 * (lo + hi), hi]
    colors = [DEFAULT_COLORS[0], DEFAULT_COLORS[0], DEFAULT_COLORS[1], DEFAULT_COLORS[2]]
    extinction = [0.0, 0.0, 0.35 * rho_max, rho_max]
    return TransferFunction(scalars, colors, extinction, name=name)


def vtk_unit_distance(tf: TransferFunction) -> float:
    """The opacity unit distance that keeps VTK's opacity a = ρ·unit ≤ 0.9 (VTK clamps a to 1)."""
    rho_max = float(tf.max_extinction)
    return 0.9 / rho_max if rho_max > 0.9 else 1.0


def update_volume_property(prop: vtkVolumeProperty, tf: TransferFunction, opacity: float = 1.0) -> None:
    """Point a vtkVolumeProperty at ``tf`` (VTK convention: ρ = opacity / unit distance); ``opacity`` scales ρ."""
    tf = tf.scaled_extinction(max(float(opacity), 0.0)) if opacity != 1.0 else tf
    unit = vtk_unit_distance(tf)
    ctf, otf = tf_to_vtk(tf, unit)
    prop.SetColor(ctf)
    prop.SetScalarOpacity(otf)
    prop.SetScalarOpacityUnitDistance(unit)


#: the lighting of a shaded volume (the setting ``shade``): ambient, diffuse, specular, specular power
SHADING = (0.3, 0.7, 0.2, 10.0)


def set_volume_shading(prop: vtkVolumeProperty, shade: bool) -> None:
    """Lighting of a vtkVolumeProperty on or off: on, each sample is lit by the scene's lights with the normal the
    scalar's gradient gives (ambient, diffuse and specular ``SHADING``), which shows the shape of the iso-structures
    that the unlit emission-absorption picture flattens."""
    ambient, diffuse, specular, power = SHADING
    prop.SetShade(1 if shade else 0)
    prop.SetAmbient(ambient)
    prop.SetDiffuse(diffuse)
    prop.SetSpecular(specular)
    prop.SetSpecularPower(power)


def vtk_volume_property(tf: TransferFunction, opacity: float = 1.0, shade: bool = False) -> vtkVolumeProperty:
    """A vtkVolumeProperty of ``tf`` (``update_volume_property``), linearly interpolated, lit with ``shade``."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    prop = vtk.vtkVolumeProperty()
    update_volume_property(prop, tf, opacity)
    prop.SetInterpolationTypeToLinear()
    set_volume_shading(prop, shade)
    return prop


def bounds_diagonal(bounds: tuple[float, ...]) -> float:
    return float(np.linalg.norm(np.subtract(bounds[1::2], bounds[0::2])))


def volume_grid(dataset: Union[Dataset, TimeSeries, pv.DataSet]) -> pv.DataSet:
    """The PyVista grid a dataset is drawn from, with scalar active (vectors shown by their magnitude)."""
    if isinstance(dataset, TimeSeries):
        dataset = dataset.frame(0)
    grid = dataset.to_pyvista() if isinstance(dataset, (TetMesh, UnstructuredMesh, CurvilinearGrid,
                                                        RegularVolume, Image2D)) else dataset
    scalars = grid.active_scalars
    if scalars is not None and np.asarray(scalars).ndim > 1:   # beside the vectors: on the points or the cells
        cells = grid.active_scalars_info.association.name == "CELL"
        (grid.cell_data if cells else grid.point_data)["magnitude"] = np.linalg.norm(np.asarray(scalars), axis=1)
        grid.set_active_scalars("magnitude", preference="cell" if cells else "point")
    return grid


def default_transfer_function_for(dataset: LoadedDataset, name: str = "default") -> TransferFunction:
    """The first-look transfer function of a dataset: placed from the histogram of its shown scalar (of every step,
    for a time series) by ``volviz.optics.auto_tf``; a compressed LOD volume gets the ramp over its range."""
    if is_lod(dataset):
        return default_transfer_function(lod_scalar_range(dataset), bounds_diagonal(lod_bounds(dataset)), name)

    return auto_transfer_function(scalar_values(dataset), mean_chord(dataset_bounds(dataset)), name)


def dataset_bounds(dataset: Union[Dataset, TimeSeries]) -> tuple[float, ...]:
    """The bounds of a dataset (the first step of a time series) from its own arrays: the bounds VTK gives its grid
    (the same to the bit on every file of ../shared/data that has points), without making that grid, so the first
    look's transfer function, placed in the scene-loading job, makes no VTK object off the GUI thread (issue #28,
    ``volviz.jobs``). What has no points of its own (a 2D image) asks VTK's grid."""
    if isinstance(dataset, TimeSeries):
        dataset = dataset.frame(0)
    if isinstance(dataset, RegularVolume):
        return tuple(float(v) for v in dataset.bounds())
    points = getattr(dataset, "points", None)
    if isinstance(dataset, Image2D) or points is None or not np.size(points):
        return tuple(volume_grid(dataset).bounds)
    flat = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    lo, hi = point_extent(flat)
    return (float(lo[0]), float(hi[0]), float(lo[1]), float(hi[1]), float(lo[2]), float(hi[2]))


def volume_input(dataset: Union[Dataset, TimeSeries]) -> MapperInput:
    """The VTK data object a volume mapper draws for ``dataset`` (tetrahedralised for non-image grids)."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    grid = transparent_nonfinite(volume_grid(dataset))
    if isinstance(dataset, RegularVolume):
        return grid
    if isinstance(dataset, TetMesh):
        return grid
    ugrid = grid if grid.GetDataObjectType() == vtk.VTK_UNSTRUCTURED_GRID else grid.cast_to_unstructured_grid()
    tets = vtk.vtkDataSetTriangleFilter()
    tets.SetInputData(ugrid)
    tets.Update()
    return tets.GetOutput()


def transparent_nonfinite(grid: pv.DataSet) -> pv.DataSet:
    """``grid`` with NaN/Inf of its active scalars replaced by a value below their finite range, which VTK's mappers
    draw transparent (the transfer functions are not clamped: ``TransferFunction.to_vtk``), as volviz's own
    renderers draw non-finite samples. Also keeps NaN out of VTK's scalar-range bookkeeping."""
    values = grid.active_scalars
    if values is None or values.dtype.kind != "f" or np.isfinite(values).all():
        return grid
    finite = values[np.isfinite(values)]
    lo, hi = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    cleaned = np.where(np.isfinite(values), values, lo - max(hi - lo, abs(lo), 1.0))
    grid = grid.copy(deep=False)
    name = grid.active_scalars_name
    assert name is not None   # the grid has active scalars (values), so they have a name
    grid.point_data[name] = cleaned.astype(values.dtype)
    grid.set_active_scalars(name)
    return grid


def add_dataset(plotter: pv.BasePlotter, dataset: Union[Dataset, TimeSeries], tf: Optional[TransferFunction] = None,
                opacity: float = 1.0, name: Optional[str] = None) -> object:
    """Add a dataset to ``plotter`` as its default visual (a volume with ``tf``); returns the VTK prop."""
    if isinstance(dataset, TimeSeries):
        return add_dataset(plotter, dataset.frame(0), tf, opacity, name)
    if isinstance(dataset, Image2D):
        return _add_image(plotter, dataset, name)

    grid = volume_grid(dataset)
    if grid.active_scalars is None or shows_no_field(dataset):
        return add_surface(plotter, surface_input(dataset, plain=True), tf, opacity, name)
    if tf is None:
        tf = default_transfer_function_for(dataset)
    if is_surface(dataset):
        return add_surface(plotter, surface_input(grid), tf, opacity, name)
    return volume_prop(plotter, volume_input(dataset), isinstance(dataset, RegularVolume), tf, opacity, name)


def volume_prop(plotter: pv.BasePlotter, data: object, regular: bool, tf: TransferFunction, opacity: float,
                name: Optional[str],
                backend: str = "auto", shade: bool = False) -> object:
    """Add a ``vtkVolume`` drawing the VTK dataset ``data`` with ``tf`` to ``plotter`` (``make_volume``): a regular
    volume by VTK's CPU ray caster where ``backend`` picks "cpu" (by default on a software OpenGL, see
    ``volviz.render.backend``). Returns the volume."""
    volume = make_volume(data, regular, tf, opacity, regular and ray_casts_on_cpu(plotter, backend), shade)
    plotter.add_actor(volume, name=name, reset_camera=False, render=False)  # type: ignore[arg-type]  # pyvista's _Wrapped decorator
    return volume


def ray_casts_on_cpu(plotter: pv.BasePlotter, backend: str = "auto") -> bool:
    """Whether ``plotter``'s regular volumes are drawn by VTK's CPU ray caster for the render option ``backend``
    (``volviz.render.backend``: by default on a software OpenGL)."""
    return choose_backend(backend, "regular", plotter_gl_info(plotter)) == "cpu"


def make_volume(data: object, regular: bool, tf: TransferFunction, opacity: float, cpu: bool = False,
                shade: bool = False) -> vtkVolume:
    """A ``vtkVolume`` drawing the VTK dataset ``data`` with ``tf``, in no renderer yet: regular volumes through
    vtkSmartVolumeMapper (its CPU ray caster with ``cpu``), lit with ``shade`` (the component setting); others
    through vtkProjectedTetrahedraMapper, which draws no lighting."""
    # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
    from volviz.render.vtk_facade import vtk

    mapper = vtk.vtkSmartVolumeMapper() if regular else vtk.vtkProjectedTetrahedraMapper()
    if regular:
        # VTK's smart mapper adapts the CPU ray caster's image sample distance only while the window asks for an
        # interactive rate and then keeps the coarse distance of the last drag: the still frame stayed blocky.
        # Adapting always (to the time each frame is allotted) gives coarse frames during a drag and full ones after.
        mapper.InteractiveAdjustSampleDistancesOff()
    if regular and cpu:
        mapper.SetRequestedRenderModeToRayCast()  # VTK's CPU ray caster
    mapper.SetInputData(data)
    volume = vtk.vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(vtk_volume_property(tf, opacity, shade and regular))
    return volume


def is_surface(dataset: Union[Dataset, TimeSeries]) -> bool:
    """Whether ``dataset`` (a time series: at its first step where the field varies) is not drawn as a volume: a
    mesh of surface cells or vertices, a grid one layer thick, geometry without a field or a constant field (the
    one rule of ``volviz.model.representation``). Such data is drawn as a surface colored by its field, or plain."""
    return representation(dataset).kind != VOLUME


def shows_no_field(dataset: Union[Dataset, TimeSeries]) -> bool:
    """Whether ``dataset`` (a volviz dataset) is geometry alone, drawn in a plain color without a scalar bar (a mesh
    with only block ids, an STL)."""
    known = isinstance(dataset, (TimeSeries, CurvilinearGrid, UnstructuredMesh))
    return known and representation(dataset).field is None


#: the point array of a surface's own colours (``surface_input``), drawn as they are by ``add_surface``
VERTEX_COLORS = "volviz vertex colours"


def surface_input(dataset: Union[Dataset, TimeSeries, pv.DataSet], plain: bool = False) -> pv.DataSet:
    """The PyVista surface drawn for a dataset of surface cells (``is_surface``; or its ``volume_grid``), its active
    scalars kept active unless they are an appearance attribute (``volviz.model.arrays.is_appearance_array``) or
    the dataset is drawn ``plain`` (geometry alone): then its vertex colours (``VERTEX_COLORS``), if it has any, else
    none. The cells touching NaN/Inf (land in an ocean field, a solver's failed points) are left out."""
    grid = volume_grid(dataset)
    name = grid.active_scalars_name
    if name is not None and (plain or is_appearance_array(name)):
        name = None
        colors = vertex_colors(dataset)
        if colors is not None and len(colors) == grid.n_points:
            grid.point_data[VERTEX_COLORS] = colors
    values = np.asarray(grid.active_scalars) if name is not None else np.zeros(0)
    if values.dtype.kind == "f" and not np.isfinite(values).all():   # cells touching NaN/Inf are not drawn
        kept: np.ndarray = np.flatnonzero(np.isfinite(values))
        grid = grid.extract_points(kept, adjacent_cells=False)
    surface = grid.extract_surface(algorithm="dataset_surface") if hasattr(grid, "extract_surface") else grid
    if surface.n_points == 0 and grid.n_points and hasattr(grid, "extract_surface"):
        surface = grid.extract_surface(algorithm=None)   # a grid of one line (170 x 1 x 1): its polyline
    if name is not None and name in surface.array_names:
        surface.set_active_scalars(name)
    else:                          # appearance alone (normals, texture coordinates, colours): no scalars
        surface.point_data.active_scalars_name = None
        surface.cell_data.active_scalars_name = None
    return surface


def add_surface(plotter: pv.BasePlotter, surface: pv.DataSet, tf: Optional[TransferFunction], opacity: float,
                name: Optional[str]) -> pv.Actor:
    """A surface made by ``surface_input``, colored by its active scalars through the transfer function's colors, or
    in its own vertex colours when it shows no array."""
    if surface.active_scalars_name is None and VERTEX_COLORS in surface.point_data:
        return plotter.add_mesh(surface, scalars=VERTEX_COLORS, rgb=True, opacity=opacity, name=name,
                                show_scalar_bar=False, reset_camera=False, render=False)
    if surface.active_scalars_name is None or tf is None:      # geometry alone: one neutral color
        return plotter.add_mesh(surface, scalars=None, color=PLAIN_COLOR, opacity=opacity, name=name,
                                show_scalar_bar=False, reset_camera=False, render=False)
    ctf, _ = tf_to_vtk(tf, 1.0)
    ctf.ClampingOn()
    actor = plotter.add_mesh(surface, scalars=surface.active_scalars_name, opacity=opacity, name=name,
                             nan_opacity=0.0, show_scalar_bar=False, reset_camera=False, render=False)
    mapper = actor.GetMapper()
    mapper.SetLookupTable(ctf)
    mapper.SetScalarRange(*tf.range)
    mapper.SetUseLookupTableScalarRange(True)
    return actor


def _add_image(plotter: Any, image: Image2D, name: Optional[str]) -> Any:
    """A 2D raster (a photo, a texture, a grey image) as a flat picture on the z = 0 plane, in its own colors (grey
    levels for one channel). Height maps open as terrain scenes instead
    (``volviz.scene.terrain.terrain_session``)."""
    grid = image.to_pyvista()
    if image.channels >= 3:
        colors = np.asarray(image.data[..., :3], dtype=np.float64).reshape(-1, 3)
        scale = float(image.maxval or max(colors.max(), 1.0))
        grid.point_data["rgb"] = np.clip(colors / scale * 255.0, 0, 255).astype(np.uint8)
        return plotter.add_mesh(grid, scalars="rgb", rgb=True, name=name, reset_camera=False, render=False)
    values = np.asarray(grid.point_data["values"], dtype=np.float64)
    finite = values[np.isfinite(values)]
    limits = (float(finite.min()), float(finite.max())) if finite.size else (0.0, 1.0)
    return plotter.add_mesh(grid, scalars="values", cmap="gray", clim=limits, show_scalar_bar=False, name=name,
                            nan_opacity=0.0, reset_camera=False, render=False)


def apply_camera(plotter: pv.BasePlotter, camera: Optional[CameraState]) -> None:
    """Set the plotter's camera from a session camera, or frame the scene from a pleasant oblique view."""
    if camera is None:
        plotter.view_isometric(render=False)  # type: ignore[call-arg]  # pyvista's _Wrapped decorator hides self from mypy
        plotter.renderer.reset_camera(render=False)   # (the plotter's own reset_camera renders in any case)
        return
    cam = plotter.camera
    cam.position = camera.position
    cam.focal_point = camera.focal_point
    cam.up = camera.view_up
    cam.view_angle = camera.view_angle
    cam.parallel_projection = camera.parallel
    cam.parallel_scale = camera.parallel_scale
    plotter.renderer.ResetCameraClippingRange()


def camera_state(plotter: pv.BasePlotter) -> CameraState:
    cam = plotter.camera
    return CameraState(position=vec3(cam.position), focal_point=vec3(cam.focal_point),
                       view_up=vec3(cam.up), view_angle=float(cam.view_angle),
                       parallel=bool(cam.parallel_projection), parallel_scale=float(cam.parallel_scale))
