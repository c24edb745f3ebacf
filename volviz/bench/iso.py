"""Benchmark: multiple semi-transparent isosurfaces (libMini note §4) — frame time, triangles drawn and image error of
the 2-pass, 3-pass and 4-pass modes against the exact mode (``volviz bench iso``).

Scenes: the Storm at an interpolated display time (4D blend of two steps), two overlapping Storm volumes (different
times, shifted), and the Blunt Fin (curvilinear, Density), each with three iso-values (one opaque, two
semi-transparent with iso-spectrum shading). Per mode: median wall time of ``--reps`` full frames (rasterise +
composite, after a warm-up), triangles a GPU would draw in the mode (opaque once, transparent once per pass; exact =
depth peeling, 2 passes per layer), fragments, RMSE / max abs error (8-bit units) against the exact mode. Also: the
iso-spectrum fits, background extraction time per 4D frame, view-dependent LOD triangle counts and geomorph popping,
and VTK's translucent rendering as a peer (same meshes; VTK lighting and constant opacity, so its error includes
shading differences; VTK's depth peeling dropped all translucent geometry on llvmpipe here). GPU rows: the same modes
drawn by VTK's OpenGL pipeline (``volviz.render.gl_iso``: multi-pass actors, depth peeling for exact; one sample per
pixel), median time of ``--reps`` frames (render + read-back of the window, after a warm-up) and the difference of
the screen (8-bit RGB, alpha 1) from the CPU compositor's image of the same mode. Writes ``docs/bench/iso.md`` +
``iso.png`` (images side by side) and optionally ``--json OUT``.
"""
from __future__ import annotations

import json
import os
import platform
import shlex
import statistics
import sys
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

from volviz.argtypes import MAX_IMAGE_SIDE, UsageParser, int_in
from volviz.bench.offscreen import bench_plotter, render_window, screenshot_rgb

from volviz.iso.animate import extract_at
from volviz.iso.composite import MODES, composite, fragments, triangles_drawn
from volviz.iso.extract import IsoMesh, IsoStyle, extract
from volviz.iso.lod import build_lod, lod_mesh, select_level
from volviz.iso.spectrum import fit_spectrum
from volviz.optics.metrics import error_heatmap, max_abs, rmse
from volviz.model.camera import Camera

DEFAULT_DATA = Path(os.environ.get("VOLVIZ_DATA", Path(__file__).resolve().parents[2].parent / "shared" / "data"))
REPO = Path(__file__).resolve().parents[2]
BG = (0.05, 0.05, 0.08, 1.0)
BLUE, GREEN, RED = (0.2, 0.45, 1.0), (0.2, 1.0, 0.35), (1.0, 0.25, 0.1)
STORM_STYLES = [IsoStyle(30, BLUE, 0.3), IsoStyle(80, GREEN, 0.4), IsoStyle(150, RED, 1.0)]
FIN_STYLES = [IsoStyle(0.7, BLUE, 0.3), IsoStyle(1.4, GREEN, 0.4), IsoStyle(3.0, RED, 1.0)]


def _median(fn: Callable[[], Any], reps: int) -> tuple[float, Any]:
    out = fn()
    times = []
    for _ in range(reps):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), out


def _shift(meshes: list[IsoMesh], offset: tuple[float, float, float]) -> list[IsoMesh]:
    return [IsoMesh(m.points + np.asarray(offset), m.triangles, m.normals, m.style, m.label) for m in meshes]


def _scenes(data: Path) -> dict[str, tuple[list[IsoMesh], Camera, str]]:
    # the readers (registry and plugins): loaded when a case first reads a file
    import volviz.io
    storm = volviz.io.read(str(data / "storm" / "Storm.pvm-t%02d"))
    s = extract_at(storm, 15.5, STORM_STYLES).meshes
    box = np.array([[0, 0, 0], [27, 27, 22.0]])
    cam = Camera.orbit(box, azimuth=35, elevation=25, distance=2.8)
    a = extract_at(storm, 10.0, STORM_STYLES).meshes
    b = _shift(extract_at(storm, 20.0, STORM_STYLES).meshes, (9.0, 6.0, 0.0))
    cam2 = Camera.orbit(np.array([[0, 0, 0], [36, 33, 22.0]]), azimuth=35, elevation=25, distance=2.6)
    fin = volviz.io.read(str(data / "bluntfin" / "bluntfinxyz.bin"))
    f = extract(fin, FIN_STYLES, scalars="Density")
    cam3 = Camera.orbit(fin.points.reshape(-1, 3), azimuth=40, elevation=30, distance=1.8)
    return {"Storm t=15.5 (4D interpolated)": (s, cam, "Storm.pvm-t15/t16 blend, iso 30/80/150"),
            "Two overlapping Storm volumes": (a + b, cam2, "t=10 and t=20 shifted by (9, 6, 0), 6 surfaces"),
            "Blunt Fin": (f, cam3, "Density iso 0.7/1.4/3.0 (curvilinear, vtkContourFilter)")}


def _vtk_blend(meshes: list[IsoMesh], cam: Camera, size: int, reps: int) -> tuple[float, np.ndarray]:
    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    import pyvista as pv
    pl = pv.Plotter(off_screen=True, window_size=[size, size])
    pl.set_background(BG[:3])  # type: ignore[arg-type]  # pyvista types its functools.wraps wrapper wrongly
    for m in meshes:
        if m.n_triangles:
            pl.add_mesh(m.to_pyvista(), color=m.style.color, opacity=float(m.style.opacity), smooth_shading=True)
    # depth peeling (enable_depth_peeling) dropped every translucent actor on this machine's llvmpipe, so the peer is
    # VTK's default translucent pass (unsorted blending, like the 2-pass mode)
    cam.apply_to(pl.camera)
    pl.renderer.ResetCameraClippingRange()

    def frame() -> np.ndarray:
        pl.render()
        return screenshot_rgb(pl)
    t, img = _median(frame, reps)
    pl.close()
    rgba = np.concatenate([img, np.ones(img.shape[:2] + (1,))], axis=-1)
    return t, rgba


def _gpu_modes(meshes: list[IsoMesh], cam: Camera, size: int, reps: int, cpu: dict[str, np.ndarray]
               ) -> dict[str, dict[str, float]]:
    """Per mode: GPU frame time (s) and RMSE / max (8-bit units) of the screen against the CPU image ``cpu[mode]``."""

    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    from volviz.render.gl_iso import GLIsoSurfaces
    pl = bench_plotter((size, size), BG[:3])
    ren_win = render_window(pl)
    cam.apply_to(pl.renderer.GetActiveCamera())
    pl.camera_set = True
    iso = GLIsoSurfaces(pl, meshes, mode="2pass")

    def frame() -> np.ndarray:
        ren_win.Render()
        return screenshot_rgb(pl)
    rows = {}
    for mode in MODES:
        iso.set_mode(mode)
        t, img = _median(frame, reps)
        rgba = np.concatenate([img, np.ones(img.shape[:2] + (1,))], axis=-1)
        ref = np.clip(cpu[mode], 0.0, 1.0)
        over = int((np.abs(rgba - ref).max(axis=-1) * 255.0 > 3.0).sum())
        rows[mode] = {"seconds": t, "rmse": rmse(rgba, ref), "max_abs": max_abs(rgba, ref), "pixels_over_3": over}
    iso.remove()
    pl.close()
    return rows


def main(argv: list[str] | None = None) -> int:
    p = UsageParser(prog="volviz bench iso", description=__doc__.split("\n\n")[0])
    p.add_argument("--data", default=str(DEFAULT_DATA), help="folder with storm/ and bluntfin/")
    p.add_argument("--size", type=int_in(1, MAX_IMAGE_SIDE), default=384, help="image width and height")
    p.add_argument("--reps", type=int_in(1, 1000), default=3, help="timed repetitions per mode (after a warm-up)")
    p.add_argument("--no-vtk", action="store_true", help="skip the VTK translucent-rendering peer")
    p.add_argument("--no-gpu", action="store_true", help="skip the GPU (VTK OpenGL) rows of the four modes")
    p.add_argument("--out", default=str(REPO / "docs" / "bench"))
    p.add_argument("--json", default=None, help="also write the results as JSON")
    args = p.parse_args(argv)
    data, out, size = Path(args.data), Path(args.out), (args.size, args.size)
    if not (data / "storm" / "Storm.pvm-t01").exists() or not (data / "bluntfin" / "bluntfinxyz.bin").exists():
        print(f"volviz bench iso: data not found under {data}", file=sys.stderr)
        return 2
    out.mkdir(parents=True, exist_ok=True)
    load_start = os.getloadavg()[0]
    command = ("volviz bench iso " + shlex.join(argv if argv is not None else sys.argv[1:])).strip()
    results: dict[str, Any] = {"command": command, "size": args.size,
                               "reps": args.reps, "machine": f"{platform.machine()}, {os.cpu_count()} cores",
                               "scenes": {}, "load_average_start": load_start}
    images: dict[str, dict[str, np.ndarray]] = {}
    for name, (meshes, cam, note) in _scenes(data).items():
        rows = {}
        fr = fragments(meshes, cam, size)
        imgs = {m: composite(fr, m, BG) for m in MODES}
        for mode in MODES:
            t, _ = _median(lambda: composite(fragments(meshes, cam, size), mode, BG), args.reps)
            tc, _ = _median(lambda: composite(fr, mode, BG), args.reps)
            rows[mode] = {"seconds": t, "composite_seconds": tc, "triangles_drawn": triangles_drawn(fr, mode),
                          "rmse": rmse(imgs[mode], imgs["exact"]), "max_abs": max_abs(imgs[mode], imgs["exact"])}
        counts = np.diff(fr.ptr)
        scene: dict[str, Any] = {
            "note": note, "triangles": fr.n_triangles, "opaque_triangles": fr.n_opaque_triangles,
            "fragments": int(len(fr.depth)), "max_depth_complexity": int(counts.max()),
            "mean_depth_complexity_covered": float(counts[counts > 0].mean()), "modes": rows}
        if not args.no_gpu:
            scene["gpu"] = _gpu_modes(meshes, cam, args.size, args.reps, imgs)
        if not args.no_vtk:
            t, vimg = _vtk_blend(meshes, cam, args.size, args.reps)
            scene["vtk_blend"] = {"seconds": t, "rmse": rmse(vimg, imgs["exact"]),
                                          "max_abs": max_abs(vimg, imgs["exact"])}
            imgs["VTK blend"] = vimg
        images[name] = imgs
        results["scenes"][name] = scene
        print(name, {m: (round(r["seconds"], 3), round(r["rmse"], 2)) for m, r in rows.items()},
              {f"{m} gpu": (round(r["seconds"], 3), round(r["rmse"], 2)) for m, r in scene.get("gpu", {}).items()},
              flush=True)
    results["spectrum_fits"] = [vars(fit_spectrum(o)) for o in (0.3, 0.4)]
    results["animation"] = _animation(data)
    results["lod"] = _lod(data, size)
    results["load_average_end"] = os.getloadavg()[0]
    _plot(images, out / "iso.png")
    _markdown(results, out / "iso.md")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=1, default=float))
    return 0


def _animation(data: Path) -> dict[str, Any]:
    # the readers (registry and plugins): loaded when a case first reads a file
    import volviz.io
    storm = volviz.io.read(str(data / "storm" / "Storm.pvm-t%02d"))
    ts = np.linspace(12.0, 14.0, 9)
    extract_at(storm, 11.5, STORM_STYLES)
    times, tris = [], []
    for t in ts:
        t0 = time.perf_counter()
        fr = extract_at(storm, float(t), STORM_STYLES)
        times.append(time.perf_counter() - t0)
        tris.append(sum(m.n_triangles for m in fr.meshes))
    return {"extract_seconds_median": statistics.median(times), "triangles_median": int(np.median(tris)),
            "frames": len(ts)}


def _lod(data: Path, size: tuple[int, int]) -> dict[str, Any]:
    # the readers (registry and plugins): loaded when a case first reads a file
    import volviz.io
    fin = volviz.io.read(str(data / "bluntfin" / "bluntfinxyz.bin"))
    (m,) = extract(fin, [FIN_STYLES[0]], scalars="Density")
    chain = build_lod(m)
    rows = []
    for d in (1.5, 3.0, 6.0, 12.0, 24.0):
        cam = Camera.orbit(fin.points.reshape(-1, 3), azimuth=40, elevation=30, distance=d)
        lam = select_level(chain, cam, size)
        rows.append({"distance_radii": d, "level": lam, "triangles": lod_mesh(chain, lam).n_triangles})
    cam = Camera.orbit(fin.points.reshape(-1, 3), azimuth=40, elevation=30, distance=3.0)
    pops = []
    for k in range(1, len(chain.levels)):
        def img(lam: float) -> np.ndarray:
            return composite(fragments([lod_mesh(chain, lam)], cam, size), "exact", BG)
        at = img(float(k))
        pops.append({"level": k, "rmse_with_morph": rmse(img(k - 1e-9), at),
                     "rmse_without_morph": rmse(img(k - 1.0), at)})
    return {"level_triangles": chain.triangle_counts, "views": rows, "popping": pops}


def _plot(images: dict[str, dict[str, np.ndarray]], path: Path) -> None:
    # optional: matplotlib (volviz[bench]), only for the figures
    import matplotlib
    matplotlib.use("Agg")
    # optional: matplotlib (volviz[bench]), only for the figures
    import matplotlib.pyplot as plt
    cols = list(next(iter(images.values())).keys())
    fig, axes = plt.subplots(2 * len(images), len(cols), figsize=(2.6 * len(cols), 5.4 * len(images)))
    for r, (name, imgs) in enumerate(images.items()):
        for c, mode in enumerate(cols):
            ax, ax2 = axes[2 * r, c], axes[2 * r + 1, c]
            ax.imshow(np.clip(imgs[mode][..., :3], 0, 1))
            ax.set_title(f"{name[:22]}\n{mode}", fontsize=7)
            ax2.imshow(error_heatmap(imgs[mode], imgs["exact"], gain=4))
            ax2.set_title(f"|{mode} − exact| ×4, RMSE {rmse(imgs[mode], imgs['exact']):.1f}", fontsize=7)
            ax.axis("off")
            ax2.axis("off")
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def _markdown(res: dict[str, Any], path: Path) -> None:
    L = ["# Multiple semi-transparent isosurfaces (libMini note §4)", "",
         f"Command: `{res['command']}` — {res['size']}² pixels, median of {res['reps']} frames after a warm-up, "
         f"{res['machine']} shared with other jobs (1-minute load {res['load_average_start']:.1f} at the start, "
         f"{res['load_average_end']:.1f} at the end). CPU rasteriser (Numba) for all four modes; error in 8-bit units "
         "of premultiplied RGBA against the exact mode (per-pixel sorted fragments).", "",
         "Triangles drawn = what a GPU draws in the mode: opaque once, transparent once per pass "
         "(2-pass: 1, 3-pass: 2, 4-pass: 3); exact as depth peeling = 2 passes per layer × max depth complexity.", ""]
    for name, sc in res["scenes"].items():
        L += [f"## {name}", "", f"{sc['note']}. {sc['triangles']} triangles ({sc['opaque_triangles']} opaque), "
              f"{sc['fragments']} fragments, depth complexity max {sc['max_depth_complexity']}, mean "
              f"{sc['mean_depth_complexity_covered']:.2f} over covered pixels.", "",
              "| mode | frame time (s) | of which compositing (s) | triangles drawn | RMSE vs exact | max vs exact |",
              "|---|---|---|---|---|---|"]
        for mode, r in sc["modes"].items():
            L.append(f"| {mode} | {r['seconds']:.3f} | {r['composite_seconds']:.4f} | {r['triangles_drawn']} | "
                     f"{r['rmse']:.2f} | {r['max_abs']:.1f} |")
        if "vtk_blend" in sc:
            v = sc["vtk_blend"]
            L.append(f"| VTK translucent blending (peer; Phong, constant opacity) | {v['seconds']:.3f} | — | — | "
                     f"{v['rmse']:.2f} | {v['max_abs']:.1f} |")
        if "gpu" in sc:
            L += ["",
                  "GPU (VTK OpenGL on this machine's driver, `volviz.render.gl_iso`): frame time (render + read-back) "
                  "and the screen's difference from the CPU image of the same mode. Pixels over 3 lie on silhouettes, "
                  "which GL's and the CPU's edge rules assign differently (checked on the Storm scene).", "",
                  "| mode | GPU frame time (s) | RMSE vs CPU mode | max vs CPU mode | pixels over 3 |",
                  "|---|---|---|---|---|"]
            for mode, r in sc["gpu"].items():
                L.append(f"| {mode} (GPU) | {r['seconds']:.3f} | {r['rmse']:.2f} | {r['max_abs']:.1f} | "
                         f"{r['pixels_over_3']} |")
        L.append("")
    L += ["## Iso-spectrum fit (least squares, α(μ) = 1 − clamp(μ^a − b, 0, 1) vs 1 − exp(−τ0/μ))", "",
          "| opacity at normal incidence | τ0 | a | b | RMS error | max error |", "|---|---|---|---|---|---|"]
    for f in res["spectrum_fits"]:
        L.append(f"| {f['opacity']} | {f['tau0']:.4f} | {f['a']:.4f} | {f['b']:.4f} | {f['rms_error']:.4f} | "
                 f"{f['max_error']:.4f} |")
    an = res["animation"]
    L += ["", "## 4D interpolation (Storm)", "",
          f"Blend + extraction of three surfaces per display frame (the background job): median "
          f"{an['extract_seconds_median'] * 1000:.1f} ms for about {an['triangles_median']} triangles "
          f"({an['frames']} frames between t = 12 and 14).", "", "## View-dependent LOD (Blunt Fin, Density 0.7)", "",
          f"Levels (triangles): {res['lod']['level_triangles']}", "",
          "| distance (bounding radii) | level λ | triangles |",
          "|---|---|---|"]
    for r in res["lod"]["views"]:
        L.append(f"| {r['distance_radii']} | {r['level']:.2f} | {r['triangles']} |")
    L += ["", "Popping at a level switch (RMSE, exact mode, just before vs at the switch):", "",
          "| switch to level | with geomorph | without (previous level) |", "|---|---|---|"]
    for r in res["lod"]["popping"]:
        L.append(f"| {r['level']} | {r['rmse_with_morph']:.2f} | {r['rmse_without_morph']:.2f} |")
    L += ["", "![modes side by side](iso.png)", ""]
    path.write_text("\n".join(L))


if __name__ == "__main__":
    raise SystemExit(main())
