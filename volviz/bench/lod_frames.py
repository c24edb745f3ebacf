"""Rendered LOD walkthrough frames for ``volviz bench compression``: a ``.vvz`` volume drawn by
``volviz.render.lod_volume.LodVolume`` along a camera orbit at a given block budget, offscreen, timed per frame
(selection + decoding + drawing) and compared with the full-resolution volume drawn by the same VTK mapper."""
from __future__ import annotations

import math
import statistics
import time
from typing import Any, Sequence

import numpy as np


def orbit(shape: Sequence[int], frames: int) -> list[tuple[tuple[float, float, float], tuple[float, float, float]]]:
    """(eye, target) pairs around the volume's centre, 15 degrees apart."""
    c = np.array(shape, float) / 2
    out = []
    for f in range(frames):
        ang = 2 * math.pi * f / 24
        eye = c + 1.6 * float(shape[0]) * np.array([math.cos(ang), math.sin(ang), 0.3])
        out.append((tuple(map(float, eye)), tuple(map(float, c))))
    return out


def _frame(plotter: Any) -> np.ndarray:
    plotter.ren_win.Render()
    return np.asarray(plotter.screenshot(return_img=True), dtype=np.float64)


def render_walkthrough(tree: Any, volume: np.ndarray, tf: Any, budgets: Sequence[int], frames: int = 6,
                       size: int = 512) -> list[dict[str, Any]]:
    """Per budget: median seconds per frame (select + decode + draw, after a warm-up frame), frames per second,
    blocks drawn, and RMSE / max (8-bit RGB) against the full-resolution volume on the same views."""
    import pyvista as pv
    import vtk

    from volviz.render.export import offscreen_plotter
    from volviz.render.lod_volume import LodVolume
    from volviz.render.vtk_scene import vtk_volume_property

    views = orbit(volume.shape, frames + 1)
    plotter = offscreen_plotter((size, size))
    try:
        plotter.set_background("black")
        # the reference: the whole volume as one block of the same mapper
        grid = pv.ImageData(dimensions=volume.shape, spacing=tuple(tree.spacing), origin=tuple(tree.origin))
        grid.point_data["scalars"] = np.asarray(volume, np.float32).ravel(order="F")
        mb = vtk.vtkMultiBlockDataSet()
        mb.SetNumberOfBlocks(1)
        mb.SetBlock(0, grid)
        mapper = vtk.vtkMultiBlockVolumeMapper()
        mapper.SetInputDataObject(mb)
        full = vtk.vtkVolume()
        full.SetMapper(mapper)
        full.SetProperty(vtk_volume_property(tf))
        plotter.renderer.AddVolume(full)
        refs = []
        for eye, target in views:
            plotter.camera_position = [eye, target, (0, 0, 1)]
            plotter.renderer.ResetCameraClippingRange()
            refs.append(_frame(plotter))
        plotter.renderer.RemoveVolume(full)
        rows = []
        for budget in budgets:
            tree.cache = type(tree.cache)(tree.cache.budget, tree.levels)   # cold cache per budget
            lod = LodVolume(plotter, tree, tf, budget=budget)
            times, blocks, errs, maxs = [], [], [], []
            for i, (eye, target) in enumerate(views):
                plotter.camera_position = [eye, target, (0, 0, 1)]
                plotter.renderer.ResetCameraClippingRange()
                t0 = time.perf_counter()
                st = lod.update()
                img = _frame(plotter)
                if i:                                   # frame 0 is the cold start
                    times.append(time.perf_counter() - t0)
                    blocks.append(st["blocks"])
                    d = img - refs[i]
                    errs.append(float(np.sqrt((d ** 2).mean())))
                    maxs.append(float(np.abs(d).max()))
            lod.remove()
            med = statistics.median(times)
            rows.append({"budget": int(budget), "render_s_per_frame": med, "fps": 1.0 / med,
                         "blocks": float(np.mean(blocks)), "rmse": float(np.mean(errs)), "max": float(max(maxs))})
        return rows
    finally:
        plotter.close()
