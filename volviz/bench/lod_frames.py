"""Rendered LOD walkthrough frames for ``volviz bench compression --animation``: a ``.vvz`` volume drawn by
``volviz.render.lod_volume.LodVolume`` along a camera orbit at given block budgets, offscreen, with both renderers
in the same run -- our one-pass ray caster (``renderer="volviz"``, ``volviz.regular.raycast``) and VTK's
``vtkMultiBlockVolumeMapper`` (``renderer="vtk"``) -- timed per frame (selection + decoding + drawing + read-back)
and compared with the exact float64 reference of the full-resolution volume (``render_reference``); VTK is also
compared with itself drawing the full volume as one block (its LOD error without its optical-model difference).

``markdown(rows)`` gives the report section; ``patch_report(path, rows)`` puts it into an existing report."""
from __future__ import annotations

import math
import statistics
import time
from pathlib import Path
from typing import Any, Optional, Sequence

import numpy as np

from volviz.model import vec3
from volviz.model.json_types import json_float, json_int

DEFAULT_PNG = Path(__file__).resolve().parents[2] / "docs" / "bench" / "compression-animation.png"
SECTION = "### Rendered walkthrough frames"


def orbit(shape: Sequence[int], frames: int) -> list[tuple[tuple[float, float, float], tuple[float, float, float]]]:
    """(eye, target) pairs around the volume's centre, 15 degrees apart."""
    c = np.array(shape, float) / 2
    out = []
    for f in range(frames):
        ang = 2 * math.pi * f / 24
        eye = c + 1.6 * float(shape[0]) * np.array([math.cos(ang), math.sin(ang), 0.3])
        out.append((vec3(eye), vec3(c)))
    return out


def _frame(plotter: Any) -> np.ndarray:
    plotter.ren_win.Render()
    return np.asarray(plotter.screenshot(return_img=True), dtype=np.float64)[..., :3]


def _err(img: np.ndarray, ref: np.ndarray) -> tuple[float, float]:
    """(RMSE, max) in 8-bit units of an 8-bit RGB frame against a reference RGB frame (0..255 floats)."""
    d = img - ref
    return float(np.sqrt((d ** 2).mean())), float(np.abs(d).max())


def _set_view(plotter: Any, eye: Any, target: Any) -> None:
    plotter.camera_position = [eye, target, (0, 0, 1)]
    plotter.renderer.ResetCameraClippingRange()


def _references(plotter: Any, tree: Any, volume: np.ndarray, tf: Any, views: list, size: int,
                ref_step: float) -> tuple[list[np.ndarray], list[np.ndarray], dict[str, float]]:
    """Per view: the exact reference (8-bit-scaled RGB over black) and VTK's full volume as one block; plus the
    reference's convergence (its step halved, on the first measured view) and its cost."""
    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    import pyvista as pv
    from volviz.render.vtk_facade import vtk

    from volviz.regular.raycast import render_reference
    from volviz.render.vtk_scene import vtk_volume_property
    from volviz.model.camera import Camera

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
    vol64 = np.asarray(volume, np.float64)
    exact, vtk_full, info = [], [], {"ref_step": ref_step}
    ref_s = []
    for i, (eye, target) in enumerate(views):
        _set_view(plotter, eye, target)
        vtk_full.append(_frame(plotter))
        cam = Camera.from_pyvista(plotter.renderer.GetActiveCamera())
        t0 = time.perf_counter()
        ref = render_reference(vol64, tree.origin, tree.spacing, tf, cam, (size, size), step=ref_step)
        ref_s.append(time.perf_counter() - t0)
        exact.append(np.clip(ref[..., :3], 0.0, 1.0) * 255.0)
        if i == 1:
            half = render_reference(vol64, tree.origin, tree.spacing, tf, cam, (size, size), step=ref_step / 2)
            info["ref_halved_rmse"], info["ref_halved_max"] = _err(exact[-1], np.clip(half[..., :3], 0, 1) * 255)
    plotter.renderer.RemoveVolume(full)
    info["ref_s"] = statistics.median(ref_s)
    info["vtk_full_rmse"], info["vtk_full_max"] = (float(np.mean([_err(v, e)[0] for v, e in
                                                                  zip(vtk_full[1:], exact[1:])])),
                                                   float(max(_err(v, e)[1] for v, e in zip(vtk_full[1:], exact[1:]))))
    return exact, vtk_full, info


def _walk(plotter: Any, tree: Any, tf: Any, budget: int, views: list, renderer: str, exact: list,
          vtk_full: list) -> tuple[dict[str, Any], np.ndarray]:
    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    from volviz.render.lod_volume import LodVolume

    tree.cache = type(tree.cache)(tree.cache.budget, tree.levels)        # cold cache per budget and renderer
    lod = LodVolume(plotter, tree, tf, budget=budget, renderer=renderer)
    times, kernel, blocks, errs, maxs, errs_v, maxs_v = [], [], [], [], [], [], []
    img = np.zeros(1)
    try:
        for i, (eye, target) in enumerate(views):
            _set_view(plotter, eye, target)
            t0 = time.perf_counter()
            st = lod.update()
            plotter.renderer.ResetCameraClippingRange()             # now with the new blocks' bounds (VTK path)
            img = _frame(plotter)
            if i:                                                   # frame 0 is the cold start
                times.append(time.perf_counter() - t0)
                kernel.append(json_float(st.get("render_s", float("nan"))))
                blocks.append(json_int(st["blocks"]))
                e, m = _err(img, exact[i])
                errs.append(e)
                maxs.append(m)
                e, m = _err(img, vtk_full[i])
                errs_v.append(e)
                maxs_v.append(m)
    finally:
        lod.remove()
    med = statistics.median(times)
    return ({"s_per_frame": med, "fps": 1.0 / med, "blocks": float(np.mean(blocks)), "rmse": float(np.mean(errs)),
             "max": float(max(maxs)), "rmse_vs_vtk_full": float(np.mean(errs_v)), "max_vs_vtk_full": float(max(maxs_v)),
             "kernel_s": statistics.median(kernel), "step": lod.step}, img)


def render_walkthrough(tree: Any, volume: np.ndarray, tf: Any, budgets: Sequence[int], frames: int = 6,
                       size: int = 512, ref_step: float = 0.5,
                       png: Optional[Path] = DEFAULT_PNG) -> list[dict[str, Any]]:
    """Per budget, for our ray caster (keys without prefix, the default renderer) and VTK's multi-block mapper
    (keys ``vtk_*``): median seconds per frame (select + decode + draw + read-back, after a cold first frame),
    frames per second, blocks drawn, RMSE / max (8-bit RGB over black) against the exact reference of the full
    volume; ``png``: last frames of each renderer beside the reference, and the time/error plot."""
    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    from volviz.render.offscreen import offscreen_plotter

    views = orbit(volume.shape, frames + 1)
    plotter = offscreen_plotter((size, size))
    rows, shots = [], {}
    try:
        plotter.set_background("black")  # type: ignore[arg-type]  # pyvista's _Wrapped decorator hides self
        exact, vtk_full, info = _references(plotter, tree, volume, tf, views, size, ref_step)
        for budget in budgets:
            ours, img_o = _walk(plotter, tree, tf, int(budget), views, "volviz", exact, vtk_full)
            theirs, img_v = _walk(plotter, tree, tf, int(budget), views, "vtk", exact, vtk_full)
            row = {"budget": int(budget), "render_s_per_frame": ours.pop("s_per_frame"), **ours,
                   **{f"vtk_{k}": v for k, v in theirs.items() if k not in ("kernel_s", "step")}, **info}
            row["speedup"] = row["vtk_s_per_frame"] / row["render_s_per_frame"]
            rows.append(row)
            shots[int(budget)] = (img_o, img_v)
        if png is not None and rows:
            _plot(rows, shots, exact[-1], Path(png))
    finally:
        plotter.close()
    return rows


def _plot(rows: list[dict[str, Any]], shots: dict[int, tuple[np.ndarray, np.ndarray]], exact: np.ndarray,
          png: Path) -> None:
    # optional: matplotlib (volviz[bench]), only for the figures
    from volviz.bench import pyplot

    plt = pyplot()

    b = [r["budget"] for r in rows]
    fig, ax = plt.subplots(1, 5, figsize=(22, 4.8))
    ax[0].plot(b, [r["render_s_per_frame"] for r in rows], "o-", label="volviz ray caster")
    ax[0].plot(b, [r["vtk_s_per_frame"] for r in rows], "s-", label="vtkMultiBlockVolumeMapper")
    ax[0].set(xscale="log", yscale="log", xlabel="block budget", ylabel="s / frame (512^2)")
    ax[0].minorticks_off()
    ax[0].set_xticks(b, [str(v) for v in b])
    ax[0].legend()
    ax[1].plot(b, [r["rmse"] for r in rows], "o-", label="volviz vs exact")
    ax[1].plot(b, [r["vtk_rmse"] for r in rows], "s-", label="VTK vs exact")
    ax[1].plot(b, [r["vtk_rmse_vs_vtk_full"] for r in rows], "s--", label="VTK vs VTK full volume")
    ax[1].set(xscale="log", xlabel="block budget", ylabel="RMSE (8-bit)")
    ax[1].minorticks_off()
    ax[1].set_xticks(b, [str(v) for v in b])
    ax[1].legend()
    top = max(shots)
    for a, img, title in ((ax[2], exact, "exact reference (full volume)"),
                          (ax[3], shots[top][0], f"volviz ray caster, budget {top}"),
                          (ax[4], shots[top][1], f"vtkMultiBlockVolumeMapper, budget {top}")):
        a.imshow(np.clip(img, 0, 255).astype(np.uint8))
        a.set_title(title, fontsize=10)
        a.axis("off")
    fig.tight_layout()
    png.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(png, dpi=80)
    plt.close(fig)


def markdown(rows: list[dict[str, Any]]) -> list[str]:
    """The report section for ``render_walkthrough``'s rows (as returned, or with a ``render_`` prefix as
    ``volviz.bench.compression`` stores them)."""
    if not rows:
        return []
    rs = [{(k[7:] if k.startswith("render_") and k != "render_s_per_frame" else k): v for k, v in r.items()}
          for r in rows]
    r0 = rs[0]
    lines = [SECTION, "",
             "The same budgets drawn offscreen at 512^2 by `volviz.render.lod_volume.LodVolume` with both renderers "
             "in the same run: our one-pass ray caster (`volviz.regular.raycast`: index grid, steps of "
             f"{r0.get('step', 0.5):g} voxel of each block's level, separable pre-integration, transparent blocks "
             "leapt over, early termination at transmittance 2e-3) and VTK's vtkMultiBlockVolumeMapper (one ray-cast "
             "pass per block). Seconds per frame = selection + decoding + drawing + screenshot read-back (median after "
             "a cold first frame, the cache cold per renderer). Errors: 8-bit RGB over black against the exact float64 "
             f"reference of the full-resolution volume (trilinear, steps of {r0['ref_step']:g} voxel, every segment "
             "integrated exactly; halving its step changes it by RMSE "
             f"{r0.get('ref_halved_rmse', float('nan')):.3f} / max {r0.get('ref_halved_max', float('nan')):.2f}; "
             f"{r0['ref_s']:.1f} s per reference frame). VTK drawing the full volume as one block scores RMSE "
             f"{r0['vtk_full_rmse']:.2f} / max {r0['vtk_full_max']:.0f} against it (its own optical model: opacity "
             "per unit distance, no pre-integration), so VTK is also compared with that image (its LOD error alone).",
             "",
             "| block budget | blocks | volviz s/frame | volviz frames/s | ray-cast kernel s | volviz RMSE | "
             "volviz max | VTK s/frame | VTK frames/s | VTK RMSE | VTK max | VTK RMSE vs VTK full | speed-up |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rs:
        lines.append(f"| {r['budget']} | {r['blocks']:.0f} | {r['render_s_per_frame']:.2f} | {r['fps']:.2f} | "
                     f"{r['kernel_s']:.2f} | {r['rmse']:.2f} | {r['max']:.0f} | {r['vtk_s_per_frame']:.2f} | "
                     f"{r['vtk_fps']:.2f} | {r['vtk_rmse']:.2f} | {r['vtk_max']:.0f} | "
                     f"{r['vtk_rmse_vs_vtk_full']:.2f} | {r['speedup']:.1f}x |")
    lines += ["", "![walkthrough](compression-animation.png)", ""]
    return lines


def patch_report(path: Path, rows: list[dict[str, Any]], notes: Sequence[str] = ()) -> None:
    """Replace the rendered-frames section of a report (from ``SECTION`` to the end) with ``markdown(rows)``."""
    text = Path(path).read_text()
    head = text.split(SECTION)[0].rstrip("\n")
    Path(path).write_text(head + "\n\n" + "\n".join(markdown(rows) + list(notes)).rstrip("\n") + "\n")
