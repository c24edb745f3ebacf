"""Slices: up to three axis-aligned planes through a regular volume, coloured by a transfer function's colours.

A session component ``{"type": "slices", "dataset": ..., "transfer_function": ..., "settings": {"x": i, "y": j,
"z": k, "array": ...}}`` (``volviz.model.settings.SlicesSettings``; an index of null: that plane is off) shows the
grid samples of plane ``x = i`` (``y = j``, ``z = k``) as an unlit, flat-coloured VTK grid in the 3D view; the app
shows the same samples as 2D images (``slice_image``). A sample ``s`` gets the colour κ(s) of the transfer function
(the chromaticity, Roettger §7.1) with ``s`` clamped to the function's range, so the whole plane is coloured, and κ
clamped to 0..1: ``slice_colors``.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Mapping, Optional

import numpy as np

from volviz.model.datasets import RegularVolume
from volviz.model.json_types import json_int
from volviz.render.component_views import VtkPropView
from volviz.render.framing import Bounds, prop_bounds
from volviz.scene.errors import SceneError

if TYPE_CHECKING:   # type-only imports for the signatures
    import numpy.typing as npt
    from volviz.render.vtk_facade import vtkRenderer

    from volviz.model.clip import ClipSettings
    from volviz.optics.transfer_function import TransferFunction

__all__ = ["AXES", "SlicesView", "drag_index", "slice_colors", "slice_image", "slice_indices", "slice_values",
           "SliceError", "value_color"]

AXES = ("x", "y", "z")


class SliceError(SceneError, ValueError):
    """A slice that the dataset cannot give (not a regular volume, an index outside the grid)."""


def _volume(dataset: Any, axis: str, index: int) -> RegularVolume:
    if not isinstance(dataset, RegularVolume):
        raise SliceError(f"slices need a regular volume, not a {getattr(dataset, 'kind', type(dataset).__name__)}")
    if axis not in AXES:
        raise SliceError(f"slice axis {axis!r} is not one of x, y, z")
    n = dataset.dimensions[AXES.index(axis)]
    if not 0 <= index < n:
        raise SliceError(f"{axis} slice {index} is outside the volume's 0..{n - 1}")
    return dataset


def slice_values(dataset: object, axis: str, index: int) -> np.ndarray:
    """The samples of plane ``axis = index`` as an image (rows, cols), row 0 at the top: for z the columns run along
    x and the rows down y; for x along y and down z; for y along x and down z."""
    data = _volume(dataset, axis, index).data
    plane = {"x": lambda: data[index, :, :], "y": lambda: data[:, index, :], "z": lambda: data[:, :, index]}[axis]()
    return np.ascontiguousarray(plane.T[::-1])


def slice_colors(values: np.ndarray, tf: TransferFunction) -> np.ndarray:
    """uint8 RGB of ``values`` (any shape): κ(clamp(s, range)) clamped to 0..1, times 255, rounded; NaN is black."""
    lo, hi = tf.range
    v = np.asarray(values, dtype=np.float64)
    rgb, _ = tf.evaluate(np.clip(v, lo, hi))     # NaN stays NaN and evaluates to black
    return np.rint(np.clip(rgb, 0.0, 1.0) * 255.0).astype(np.uint8)


def value_color(tf: TransferFunction, value: float) -> tuple[float, float, float]:
    """The colour (0..1) a slice gives ``value``: a new isosurface's default colour, so that it matches the planes."""
    rgb = slice_colors(np.array([value]), tf)[0]
    return (float(rgb[0]) / 255.0, float(rgb[1]) / 255.0, float(rgb[2]) / 255.0)


def slice_image(dataset: object, axis: str, index: int, tf: TransferFunction) -> np.ndarray:
    """The (rows, cols, 3) uint8 image of one slice, row 0 at the top (``slice_values`` through ``slice_colors``)."""
    return slice_colors(slice_values(dataset, axis, index), tf)


def slice_indices(settings: Mapping[str, object]) -> dict[str, int]:
    """The planes that are on in a slices component's settings, by axis."""
    return {axis: json_int(settings[axis]) for axis in AXES if settings.get(axis) is not None}


def drag_index(dataset: object, axis: str, anchor: npt.ArrayLike, origin: npt.ArrayLike, direction: npt.ArrayLike
               ) -> int:
    """The index of plane ``axis`` a drag has moved to: the grid index nearest the point of the line through
    ``anchor`` (where the plane was grabbed) along the axis that is closest to the mouse ray (``origin``,
    ``direction``), clamped to the grid; a ray along the axis leaves the plane where it was grabbed."""
    volume = _volume(dataset, axis, 0)
    a = AXES.index(axis)
    p = np.asarray(anchor, dtype=np.float64)
    o = np.asarray(origin, dtype=np.float64)
    d = np.asarray(direction, dtype=np.float64)
    d = d / np.linalg.norm(d)
    w = p - o
    denom = 1.0 - d[a] ** 2                  # the axis is the unit vector e_a: |e_a x d|^2
    s = 0.0 if denom < 1e-12 else (d[a] * float(d @ w) - w[a]) / denom
    index = int(np.rint((p[a] + s - volume.origin[a]) / volume.spacing[a]))
    return int(np.clip(index, 0, volume.dimensions[a] - 1))


def _plane_grid(volume: RegularVolume, axis: str, index: int, tf: Any) -> Any:
    """A one-sample-thick ImageData at plane ``axis = index`` with the slice's colours as point data."""
    # heavy: PyVista (about 180 modules), loaded only when a slice plane is made
    import pyvista as pv

    a = AXES.index(axis)
    dims = list(volume.dimensions)
    dims[a] = 1
    origin = list(volume.origin)
    origin[a] += index * volume.spacing[a]
    grid = pv.ImageData(dimensions=dims, spacing=volume.spacing, origin=origin)
    plane = np.take(volume.data, [index], axis=a)                 # (nx, ny, nz) with one sample along the axis
    grid.point_data["slice_rgb"] = slice_colors(plane, tf).reshape(-1, 3, order="F")
    return grid


class SlicesView(VtkPropView):
    """The planes of a slices component as flat-coloured VTK actors in one prop assembly (``actors``: by axis).
    ``set_tf`` recolours them; ``set_indices`` moves them (no rebuild of the scene); ``plane_at`` says which plane
    is under a pixel (the app drags it). The scene's clipping does not cut them."""

    kind = "slices"

    def __init__(self, plotter: Any, comp: Any, dataset: Any, tf: Any) -> None:
        super().__init__(None)
        self.plotter, self.comp_id, self.dataset, self.tf = plotter, comp.id, dataset, tf
        self.indices = slice_indices(comp.settings)
        self.actors: dict[str, Any] = {}
        try:
            for axis, index in self.indices.items():
                _volume(dataset, axis, index)                      # a bad index fails here, before any actor
        except SliceError as exc:
            raise SliceError(f"component {comp.id!r}: {exc}") from None
        self._show()

    def _show(self) -> None:
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        visible = True
        if self.prop is not None:
            visible = bool(self.prop.GetVisibility())
            self.plotter.remove_actor(self.prop, render=False)
        assembly = vtk.vtkPropAssembly()
        self.actors = {}
        for axis, index in self.indices.items():
            mapper = vtk.vtkDataSetMapper()
            mapper.SetInputData(_plane_grid(self.dataset, axis, index, self.tf))
            mapper.SetScalarModeToUsePointFieldData()
            mapper.SelectColorArray("slice_rgb")
            mapper.SetColorModeToDirectScalars()
            mapper.ScalarVisibilityOn()
            actor = vtk.vtkActor()
            actor.SetMapper(mapper)
            actor.GetProperty().LightingOff()
            assembly.AddPart(actor)
            self.actors[axis] = actor
        assembly.SetVisibility(visible)
        self.prop = assembly
        self.plotter.add_actor(assembly, name=self.comp_id, reset_camera=False, render=False)

    def set_indices(self, indices: dict[str, int]) -> None:
        """Show the planes ``indices`` (axis -> index) instead (not rendered)."""
        for axis, index in indices.items():
            _volume(self.dataset, axis, index)
        self.indices = dict(indices)
        self._show()

    def plane_at(self, renderer: vtkRenderer, x: float, y: float) -> Optional[tuple[str, np.ndarray]]:
        """The plane under display pixel (x, y) of ``renderer`` (VTK's coordinates, y up) and the world point hit
        on it; None when no plane is there or the planes are hidden."""
        # heavy: VTK (all of it, through vtk_facade), loaded where VTK objects are made
        from volviz.render.vtk_facade import vtk

        if self.prop is None or not self.prop.GetVisibility() or not self.actors:
            return None
        picker = vtk.vtkCellPicker()
        picker.SetTolerance(0.0005)
        picker.PickFromListOn()
        for actor in self.actors.values():
            picker.AddPickList(actor)
        if not picker.Pick(float(x), float(y), 0.0, renderer):
            return None
        actor = picker.GetActor()
        axis = next((a for a, part in self.actors.items() if part is actor), None)
        return None if axis is None else (axis, np.asarray(picker.GetPickPosition(), dtype=np.float64))

    def set_tf(self, tf: Optional[TransferFunction], opacity: float = 1.0) -> None:
        """Recolour the planes with ``tf``'s colours (the opacity does not apply: a slice is opaque)."""
        if tf is not None:
            self.tf = tf
            self._show()

    def set_clip(self, clip: ClipSettings) -> bool:
        """Slices are not clipped."""
        return True

    def bounds(self) -> Optional[Bounds]:
        return prop_bounds(self.prop) if self.indices else None

    def remove(self) -> None:
        self.plotter.remove_actor(self.prop, render=False)
