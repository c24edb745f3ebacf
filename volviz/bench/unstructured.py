"""``volviz bench unstructured``: the Blunt Fin (PLOT3D, Density, 5-split tetrahedra) at 512^2, perspective, along a
fixed camera path; method "pt" against the exact "reference" and VTK's three unstructured volume mappers with the same
transfer function, in the same run. Writes docs/bench/unstructured.md, a time-vs-error plot and a side-by-side image
with x8 error heat maps.

Transfer-function convention for VTK: the same kappa (vtkColorTransferFunction, RGB) and opacity a = rho x
unit_distance with ScalarOpacityUnitDistance = unit_distance (VTK's unstructured mappers behave as if
rho = a / unit_distance: docs/design.md "Opacity conventions differ"). VTK images are read back against a black
background, i.e. as premultiplied RGB, so every method is compared on the RGB channels (pt also on RGBA).
"""
from __future__ import annotations

import argparse
import json
import os
import shlex
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from volviz.argtypes import MAX_IMAGE_SIDE, UsageParser, int_in
from volviz.bench.offscreen import bench_plotter, finish, render_window, screenshot_rgb, timed_renders
from volviz.model.camera import Camera
from volviz.optics import TransferFunction
from volviz.optics.metrics import error_heatmap, max_abs, rmse

DEFAULT_DATA = Path(os.environ.get("VOLVIZ_DATA", Path(__file__).resolve().parents[2].parent / "shared" / "data"))
VTK_MAPPERS = ("vtkProjectedTetrahedraMapper", "vtkUnstructuredGridVolumeRayCastMapper",
               "vtkUnstructuredGridVolumeZSweepMapper")


ONLY_ROWS = ("sort", "large", "cpu", "exact")


def _only_list(text: str) -> list[str]:
    """An argument type: a comma list of ``ONLY_ROWS`` names."""
    names = [t for t in text.split(",") if t]
    unknown = [name for name in names if name not in ONLY_ROWS]
    if unknown or not names:
        raise argparse.ArgumentTypeError(f"unknown row {(unknown or [text])[0]!r} (known: {', '.join(ONLY_ROWS)})")
    return names


def _mapper_list(text: str) -> str:
    """An argument type: 'all', 'none' or a comma list of ``VTK_MAPPERS`` names, kept as text."""
    unknown = [name for name in text.split(",") if name not in VTK_MAPPERS] if text not in ("all", "none") else []
    if unknown:
        raise argparse.ArgumentTypeError(f"unknown VTK mapper {unknown[0]!r} (known: {', '.join(VTK_MAPPERS)})")
    return text


def bluntfin_tf() -> Any:
    """The Density transfer function used by the benchmark and the tests (rho per unit length of the grid)."""
    return TransferFunction([0.19, 1.0, 2.0, 3.0, 5.0],
                            [[0.2, 0.3, 1.0], [0.2, 0.9, 0.9], [1.0, 0.9, 0.2], [1.0, 0.3, 0.1], [1.0, 1.0, 1.0]],
                            [0.0, 0.05, 0.3, 0.8, 0.0], name="bluntfin-density")


def camera_path(points: np.ndarray, n: int) -> list[Any]:
    """n perspective views orbiting the fin (azimuth 20..110 degrees, elevation 25, 30 degree view angle)."""
    return [Camera.orbit(points, 20.0 + 90.0 * i / max(n - 1, 1), 25.0, 1.6, view_angle=30.0, up=(0, 0, 1))
            for i in range(n)]


def _vtk_render(mesh: Any, tf: Any, cam: Any, size: int | tuple[int, int], mapper_name: str, reps: int,
                grid: Any = None) -> tuple[np.ndarray, list[float]]:
    """One of VTK's volume mappers on ``mesh`` (or on ``grid`` when given, e.g. an image for the GPU ray caster) in an
    offscreen window of ``size`` (N or (W, H)): the image of the last of ``reps`` timed draws, each to the GPU's
    completion, as float RGB over black."""
    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    from volviz.render.vtk_facade import vtk_to_numpy, vtk

    from volviz.render.vtk_tf import tf_to_vtk

    w, h = (size, size) if isinstance(size, int) else size
    mapper = getattr(vtk, mapper_name)()
    mapper.SetInputData(mesh.to_pyvista() if grid is None else grid)
    if mapper_name == "vtkSmartVolumeMapper":
        mapper.SetRequestedRenderModeToGPU()                            # the GPU ray caster, as in VTK's own apps
    ctf, otf = tf_to_vtk(tf, 1.0)
    prop = vtk.vtkVolumeProperty()
    prop.SetColor(ctf)
    prop.SetScalarOpacity(otf)
    prop.SetScalarOpacityUnitDistance(1.0)
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOff()
    vol = vtk.vtkVolume()
    vol.SetMapper(mapper)
    vol.SetProperty(prop)
    ren = vtk.vtkRenderer()
    ren.SetBackground(0, 0, 0)
    ren.AddVolume(vol)
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(w, h)
    win.AddRenderer(ren)
    cam.apply_to(ren.GetActiveCamera())
    ren.ResetCameraClippingRange()
    times = timed_renders(win, reps)
    w2i = vtk.vtkWindowToImageFilter()
    w2i.SetInput(win)
    w2i.SetInputBufferTypeToRGB()
    w2i.ReadFrontBufferOff()
    w2i.Update()
    arr = vtk_to_numpy(w2i.GetOutput().GetPointData().GetScalars()).reshape(h, w, 3)[::-1]
    win.Finalize()
    return arr.astype(np.float64) / 255.0, times


def _rgb_err(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    return rmse(a[..., :3], b[..., :3]), max_abs(a[..., :3], b[..., :3])


def _size_list(text: str) -> list[tuple[int, int]]:
    """An argument type: a comma list of window sizes, each N (square) or WxH."""
    out = []
    for item in (t.strip() for t in text.split(",") if t.strip()):
        w, _, h = item.lower().partition("x")
        try:
            size = (int(w), int(h or w))
        except ValueError:
            raise argparse.ArgumentTypeError(f"window size must be N or WxH, got {item!r}") from None
        if not all(1 <= v <= MAX_IMAGE_SIDE for v in size):
            raise argparse.ArgumentTypeError(f"window size out of range 1..{MAX_IMAGE_SIDE}: {item!r}")
        out.append(size)
    return out


def gl_pt_frames(mesh: Any, tf: Any, cams: list[Any], size: tuple[int, int], reps: int, lookup: str = "3d",
                 split: bool = False, same: bool = False) -> tuple[dict[str, Any], np.ndarray]:
    """Method "pt-gl" (``volviz.render.gl_pt``) in an offscreen PyVista window of ``size``: a warm-up render
    (shader compile, table and vertex buffer upload), then ``reps`` passes over the cameras, each render for a new
    camera (so each includes the sort and the index buffer upload). Returns the medians (wall ``frame_s``, the
    sort and order-building seconds of the frame, the order texture's upload call ``upload_s`` where the volume
    draws its order as a texture, the process CPU time ``cpu_s``, which on a software rasteriser includes its
    threads) and the RGB image of ``cams[0]`` (float, premultiplied over black), plus the OpenGL renderer
    string.

    ``split``: also take the frame apart, for each camera after its timed frame: the same frame again (no new sort
    or index buffer: ``same_s``), then with an index buffer of one cell (its first render rebuilds that small index
    buffer; the second, ``one_cell_s``, is a draw submission whose vertex and fragment work is negligible: the
    Python callbacks, uniforms, VTK's render traversal and the driver's draw call). These three are the process's
    CPU seconds (llvmpipe's threads included; other jobs on the machine are not), paired per camera; medians:
    ``ibo_s`` = frame - same - sort - order (VTK's index buffer build and upload; sort and order are the volume's
    own timings), ``draw_work_s`` = same - one_cell (the full draw's vertex and fragment work, which a GPU takes
    off the CPU) and ``cpu_side_proper_s`` = sort + order + ibo_s + one_cell_s.

    ``same``: also draw each camera a second time (no new sort or order), wall seconds to the GPU's completion
    (``draw_s``): the draw alone, what a frame costs while the camera rests."""

    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    from volviz.render.gl_pt import GLPTVolume

    pl = bench_plotter(size, "black")
    ren_win = render_window(pl)
    vol = GLPTVolume(pl, mesh, tf, lookup=lookup)
    cams[0].apply_to(pl.renderer.GetActiveCamera())
    pl.camera_set = True
    pl.screenshot(return_img=True)
    frame, cpu, sort, order, same_cpu, one, draw = [], [], [], [], [], [], []  # same_cpu, one: CPU seconds
    upload: list[float] = []                     # the order texture's upload call, timed by the volume
    for _ in range(reps):
        for cam in cams[1:] + cams[:1] if len(cams) > 1 else cams * 2:     # each render a new camera
            cam.apply_to(pl.renderer.GetActiveCamera())
            t0, c0 = time.perf_counter(), time.process_time()
            ren_win.Render()
            finish(ren_win)
            frame.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
            sort.append(vol.stats["sort_s"])
            order.append(vol.stats["order_s"])
            if "upload_s" in vol.stats:
                upload.append(vol.stats["upload_s"])
            if same:
                draw.extend(timed_renders(ren_win, 1))
            if split:
                same_cpu.append(_timed_render(pl))
                restore = _one_cell_order(vol)
                ren_win.Render()
                one.append(_timed_render(pl))
                restore()
                ren_win.Render()
    cams[0].apply_to(pl.renderer.GetActiveCamera())
    ren_win.Render()
    img = screenshot_rgb(pl)
    caps = ren_win.ReportCapabilities() or ""
    renderer = next((ln.split(":", 1)[1].strip() for ln in caps.splitlines() if "renderer string" in ln), "")
    vol.remove()
    pl.close()
    res = {"frame_s": float(np.median(frame)), "cpu_s": float(np.median(cpu)), "sort_s": float(np.median(sort)),
           "order_s": float(np.median(order)), "frames_timed": len(frame), "lookup": lookup, "gl_renderer": renderer,
           "order_texture": bool(vol.order_texture), "gpu_bytes_per_cell": vol.gpu_bytes() / mesh.n_cells}
    if same:
        res["draw_s"] = float(np.median(draw))
    if upload:
        res["upload_s"] = float(np.median(upload))
    if split:
        f, sa, on, so, od = (np.array(v) for v in (cpu, same_cpu, one, sort, order))
        res["same_s"], res["one_cell_s"] = float(np.median(sa)), float(np.median(on))
        res["ibo_s"] = float(np.median(np.maximum(f - sa - so - od, 0.0)))
        res["draw_work_s"] = float(np.median(sa - on))
        res["cpu_side_proper_s"] = float(np.median(so + od + np.maximum(f - sa - so - od, 0.0) + on))
    return res, img


def _timed_render(pl: Any) -> float:
    """The process CPU seconds of one render."""
    c0 = time.process_time()
    pl.ren_win.Render()
    finish(pl.ren_win)
    return time.process_time() - c0


def _one_cell_order(vol: Any) -> Any:
    """Draw only the first cell of ``vol``'s order (the 4 triangles of one tetrahedron) until the camera changes;
    returns the function that puts the volume's own index buffer back. With the order texture the static index
    buffer is cut to its first slot too (else the vertex shader still runs over every slot, work a GPU does), and
    put back by that function (VTK rebuilds it at the next render, which the caller does not time)."""
    vol._set_index_buffer(vol.order[:1], np.ones(vol.topo.n_tets, bool))
    if not getattr(vol, "order_texture", False):
        return lambda: None
    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    from volviz.render.vtk_facade import vtk

    full = vol.polydata.GetPolys()
    conn = full.GetConnectivityArray()
    one = vtk.vtkCellArray()
    for tri in range(4):                                 # the first slot's triangles
        one.InsertNextCell(3)
        for k in range(3):
            one.InsertCellPoint(int(conn.GetValue(3 * tri + k)))
    vol.polydata.SetPolys(one)

    def restore() -> None:
        vol.polydata.SetPolys(full)
    return restore


def main(argv: list[str] | None = None) -> int:
    p = UsageParser(prog="volviz bench unstructured", description=__doc__.split("\n\n")[0])
    p.add_argument("--dataset", default=str(DEFAULT_DATA / "bluntfin"), help="folder with bluntfinxyz.bin/q.bin")
    p.add_argument("--size", type=int_in(1, MAX_IMAGE_SIDE), default=512, help="image width and height")
    p.add_argument("--frames", type=int_in(1, 10_000), default=4, help="camera path length")
    p.add_argument("--reps", type=int_in(1, 1000), default=3, help="timed repetitions per frame (after a warm-up)")
    p.add_argument("--sort", default="mpvo", choices=("mpvo", "centroid", "power"))
    p.add_argument("--lookup", default="auto", choices=("auto", "separable", "3d"), help="pre-integration lookup")
    p.add_argument("--no-compare-3d", dest="compare_3d", action="store_false",
                   help="skip the extra pt run with the 3D table")
    p.add_argument("--vtk", type=_mapper_list, default="all",
                   help=f"comma list of VTK mappers to run ({', '.join(VTK_MAPPERS)}), 'all' or 'none'")
    p.add_argument("--no-gl", dest="gl", action="store_false",
                   help="skip method pt-gl (volviz's pre-integrated PT through VTK's OpenGL)")
    p.add_argument("--gl-lookup", default="3d", choices=("auto", "separable", "3d"), help="pt-gl's lookup")
    p.add_argument("--scan", type=_size_list, default=[],
                   help="also time pt, pt-gl and vtkProjectedTetrahedraMapper at these window sizes "
                        "(comma list of N or WxH, e.g. 256,512,1024,1920x1080; 2 cameras, 1 frame each)")
    p.add_argument("--scan-reps", type=int_in(1, 100), default=1,
                   help="timed frames per camera and method in the --scan rows (after a warm-up)")
    p.add_argument("--raycast-grid", type=int_in(0, 1024), default=0,
                   help="also time VTK's GPU ray caster in the --scan rows on the mesh resampled to N³ (0: not)")
    p.add_argument("--exact", type=_size_list, default=[],
                   help="window sizes at which pt-gl and vtkProjectedTetrahedraMapper are compared with the exact "
                        "reference (comma list of N or WxH)")
    p.add_argument("--sort-sizes", type=_size_list, default=_size_list("256,512,1024,1920x1080,3840x2160"),
                   help="window sizes of the sort-seconds table (comma list of N or WxH; empty: no table)")
    p.add_argument("--cpu-sizes", type=_size_list, default=_size_list("512,1920x1080,3840x2160"),
                   help="window sizes at which pt-gl's CPU side is taken apart, beside 64² (2 cameras, 1 frame each)")
    p.add_argument("--interactive-sizes", type=_size_list, default=_size_list("1920x1080,3840x2160"),
                   help="window sizes of the interactive-resolution rows: pt-gl's reduced-resolution drag frames "
                        "against its full-resolution frames (comma list of N or WxH; empty: no rows)")
    p.add_argument("--interactive-pixels", type=int_in(1, MAX_IMAGE_SIDE ** 2), default=None,
                   help="pt-gl's pixel cap during an interaction (default: volviz.render.reduced_fill's, 1920x1080)")
    p.add_argument("--large-refine", type=float, default=0.0,
                   help="also sort the Blunt Fin refined by this factor per axis (2.3: 2.27 M tetrahedra; 0: not)")
    p.add_argument("--large-out", default=None,
                   help="also write that refined mesh to this VTK .vtu file (Density on the points)")
    p.add_argument("--only", type=_only_list, default=None,
                   help="run only these rows (comma list of 'sort': the sort table and the index buffer, 'large': "
                        "the large mesh, which needs --large-refine, 'cpu': the CPU side against --cpu-sizes) and "
                        "splice them into the existing "
                        "unstructured.md under --out, each block naming this command")
    p.add_argument("--out", default=str(Path(__file__).resolve().parents[2] / "docs" / "bench"))
    p.add_argument("--json", default=None, help="also write the results as JSON")
    args = p.parse_args(argv)
    if args.only is not None:
        if "large" in args.only and args.large_refine <= 1.0:
            p.error("--only large needs --large-refine > 1")
        if "sort" in args.only and not args.sort_sizes:
            p.error("--only sort needs --sort-sizes")
        if "cpu" in args.only and not args.cpu_sizes:
            p.error("--only cpu needs --cpu-sizes")
        if "exact" in args.only and not args.exact:
            p.error("--only exact needs --exact")
        return only_rows(args, argv)

    # the kernels (Numba) of this case only: a bench loads what its cases run
    from volviz.io.plot3d import read_plot3d
    from volviz.unstructured.render import render
    from volviz.unstructured.tetrahedralize import tetrahedralize

    load_start = os.getloadavg()[0]
    ds = Path(args.dataset)
    grid = read_plot3d(ds / "bluntfinxyz.bin", ds / "bluntfinq.bin")
    mesh, rep = tetrahedralize(grid, "Density", report=True)
    tf = bluntfin_tf()
    size = (args.size, args.size)
    cams = camera_path(mesh.points, args.frames)
    print(f"Blunt Fin: {rep.n_tets} tetrahedra ({rep.n_degenerate} degenerate dropped of "
          f"{rep.n_tets + rep.n_degenerate}), {args.size}^2, {len(cams)} frames", flush=True)

    def run_path(lookup: str) -> dict[str, Any]:
        """The camera path as a movie export renders it: frame i + 1 sorted in the background while frame i draws
        (``volviz.unstructured.prefetch.render_path``); median wall time per frame over ``reps`` passes."""
        # the kernels (Numba) of this case only: a bench loads what its cases run
        from volviz.unstructured.prefetch import render_path

        frame_s, waits = [], []
        for _ in range(args.reps):
            t_prev = time.perf_counter()
            for img, st in render_path(mesh, tf, cams, size, sort=args.sort, lookup=lookup):
                now = time.perf_counter()
                frame_s.append(now - t_prev)
                waits.append(st.sort_s)
                t_prev = now
        res = {"frame_s": float(np.median(frame_s)), "sort_wait_s": float(np.median(waits)), "lookup": lookup}
        print(f"pt path with background sort: {res}", flush=True)
        return res

    def run_pt(lookup: str) -> tuple[dict[str, Any], list[np.ndarray]]:
        """Warm-up (compile + table), then ``reps`` timed frames per camera; medians of the per-camera medians."""
        render(mesh, tf, cams[0], size, "pt", sort=args.sort, lookup=lookup)
        rows, imgs = [], []
        for cam in cams:
            runs = []
            for _ in range(args.reps):
                c0 = time.process_time()
                img, st = render(mesh, tf, cam, size, "pt", sort=args.sort, lookup=lookup, return_stats=True)
                st.extra["cpu_s"] = time.process_time() - c0
                runs.append(st)
            imgs.append(img)
            rows.append(sorted(runs, key=lambda s: s.total_s)[len(runs) // 2])
        res: dict[str, Any] = {k: float(np.median([getattr(s, k) for s in rows]))
                               for k in ("sort_s", "project_s", "raster_s", "total_s")}
        res["cpu_s"] = float(np.median([s.extra["cpu_s"] for s in rows]))
        res["cycles"] = int(sum(s.cycles for s in rows))
        res["boundary_relations"] = int(np.median([s.boundary_relations for s in rows]))
        res["fragments"] = int(np.median([s.fragments for s in rows]))
        res["lookup"] = lookup
        print(f"pt ({lookup}): {res}", flush=True)
        return res, imgs

    pt, pt_imgs = run_pt(args.lookup)
    along = run_path(args.lookup)
    pt3, pt3_imgs = run_pt("3d") if args.lookup != "3d" and args.compare_3d else (None, None)

    # --- reference on frame 0
    t0 = time.perf_counter()
    ref = render(mesh, tf, cams[0], size, "reference")
    ref_s = time.perf_counter() - t0
    print(f"reference: {ref_s:.1f} s", flush=True)

    results: dict[str, Any] = {
        "command": "volviz bench unstructured " + " ".join(shlex.quote(a) for a in (argv if argv is not None
                                                                                    else sys.argv[1:])),
        "n_tets": rep.n_tets, "n_degenerate": rep.n_degenerate, "size": args.size, "frames": len(cams),
        "load_average_start": load_start,
        "methods": {},
    }
    e_rgb = _rgb_err(pt_imgs[0], ref)
    results["methods"]["pt"] = {
        **pt, "frame_s": pt["total_s"], "tets_per_s": rep.n_tets / pt["total_s"],
        "sort_tets_per_s": rep.n_tets / pt["sort_s"],
        "rmse_rgb": e_rgb[0], "max_rgb": e_rgb[1],
        "rmse_rgba": rmse(pt_imgs[0], ref), "max_rgba": max_abs(pt_imgs[0], ref)}
    results["methods"]["reference"] = {"frame_s": ref_s, "rmse_rgb": 0.0, "max_rgb": 0.0}
    images = {"reference": ref, "pt": pt_imgs[0]}
    if pt3 is not None:
        assert pt3_imgs is not None
        e3 = _rgb_err(pt3_imgs[0], ref)
        results["methods"]["pt-3d"] = {**pt3, "frame_s": pt3["total_s"], "tets_per_s": rep.n_tets / pt3["total_s"],
                                       "rmse_rgb": e3[0], "max_rgb": e3[1], "rmse_rgba": rmse(pt3_imgs[0], ref),
                                       "max_rgba": max_abs(pt3_imgs[0], ref)}

    if args.gl:
        gl, gl_img = gl_pt_frames(mesh, tf, cams, size, args.reps, args.gl_lookup)
        e = _rgb_err(gl_img, ref)
        gl64, _ = gl_pt_frames(mesh, tf, cams, (64, 64), args.reps, args.gl_lookup, split=True)
        results["gl_renderer"] = gl.pop("gl_renderer")
        results["methods"]["pt-gl"] = {**gl, "rmse_rgb": e[0], "max_rgb": e[1],
                                       "tets_per_s": rep.n_tets / gl["frame_s"], "cpu_side_s": gl64["frame_s"],
                                       "cpu_side_cpu_s": gl64["cpu_s"], "cpu_side_sort_s": gl64["sort_s"],
                                       "cpu_side_order_s": gl64["order_s"],
                                       **{f"cpu_side_{k}": gl64[k] for k in ("ibo_s", "one_cell_s", "draw_work_s")},
                                       "cpu_side_proper_s": gl64["cpu_side_proper_s"]}
        images["pt-gl"] = gl_img
        print(f"pt-gl: {results['methods']['pt-gl']}", flush=True)
        if args.cpu_sizes:
            results["cpu_side"] = cpu_side_scan(mesh, tf, cams[:2], [(64, 64), *args.cpu_sizes], args.gl_lookup,
                                                args.reps)
        if args.interactive_sizes:
            results["interactive"] = interactive_rows(mesh, tf, cams[:2], args.interactive_sizes, args.reps,
                                                      args.gl_lookup, args.interactive_pixels)
    if args.large_refine > 1.0:
        big_mesh = refined_bluntfin(grid, args.large_refine)
        if args.large_out:
            write_vtu(big_mesh, args.large_out)
        results["large"] = large_mesh_row(big_mesh, tf, cams[:2], args.reps)
        results["large"]["refine"] = args.large_refine
    if args.sort_sizes:
        two = cams[:2] if len(cams) > 1 else cams * 2
        results["sort_scan"] = sort_scan(mesh, two, args.sort_sizes, args.reps)
        results["index_buffer"] = index_buffer_row(mesh, tf, two, args.reps)

    results["methods"]["pt"]["path"] = along
    covered = int((pt_imgs[0][..., 3] > 0).sum())
    results["methods"]["pt"]["covered_px"] = covered
    results["methods"]["pt"]["early_terminated_px"] = int((pt_imgs[0][..., 3] >= 0.999).sum())
    mappers = VTK_MAPPERS if args.vtk == "all" else () if args.vtk == "none" else tuple(args.vtk.split(","))
    for name in mappers:
        zsweep = "ZSweep" in name
        _vtk_render(mesh, tf, cams[0], args.size, name, 1)           # warm-up
        times, img0 = [], None
        for i, cam in enumerate(cams[:1] if zsweep else cams):
            img, t = _vtk_render(mesh, tf, cam, args.size, name, 1 if zsweep else max(1, args.reps - 1))
            times.extend(t)
            if i == 0:
                img0 = img
        assert img0 is not None                                        # cams is not empty
        e = _rgb_err(img0, ref)
        frame_s = float(np.median(times))
        results["methods"][name] = {"frame_s": frame_s, "tets_per_s": rep.n_tets / frame_s, "rmse_rgb": e[0],
                                    "max_rgb": e[1], "frames_timed": len(times)}
        images[name] = img0
        print(f"{name}: {results['methods'][name]}", flush=True)

    if "vtkProjectedTetrahedraMapper" in mappers:
        # the same mapper on a 64^2 window: its per-frame CPU work (sort, projection, triangle setup) without the
        # fill of the 512^2 fragments, which is what a shader path on llvmpipe would have to beat
        _vtk_render(mesh, tf, cams[0], 64, "vtkProjectedTetrahedraMapper", 1)
        t64 = [t for cam in cams for t in _vtk_render(mesh, tf, cam, 64, "vtkProjectedTetrahedraMapper",
                                                         max(1, args.reps - 1))[1]]
        results["vtk_pt_64_s"] = float(np.median(t64))

    if args.scan:
        results["scan"] = _size_scan(mesh, tf, cams[:2], args.scan, args.gl_lookup, args.sort, args.lookup,
                                     args.scan_reps, args.raycast_grid)
    if args.exact:
        results["exact"] = exact_rows(mesh, tf, cams[0], args.exact, args.gl_lookup)

    results["load_average_end"] = os.getloadavg()[0]
    vtk_best = min((v["frame_s"] for k, v in results["methods"].items() if k.startswith("vtk")), default=None)
    if vtk_best:
        results["speedup_vs_fastest_vtk"] = vtk_best / pt["total_s"]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    _plots(results, images, ref, out)
    _markdown(results, out / "unstructured.md")
    if args.json:
        Path(args.json).write_text(json.dumps(results, indent=2))
    return 0


#: the sort rows of the window-size table: (label, method, nonconvex)
SORT_ROWS = (("mpvo (object-space boundary relations)", "mpvo", "auto"),
             ("mpvo (boundary relations sampled at the pixel centres, before #29)", "mpvo", "sample"),
             ("centroid", "centroid", "auto"), ("power", "power", "auto"))


def only_rows(args: argparse.Namespace, argv: list[str] | None) -> int:
    """``--only``: the sort table (with the Blunt Fin's index buffer row) and/or the large mesh, each block spliced
    into the existing report (``splice``), which keeps every other row of the run that made it."""
    # the kernels (Numba) of this case only: a bench loads what its cases run
    from volviz.io.atomic import atomic_write_text
    from volviz.io.plot3d import read_plot3d
    from volviz.unstructured.tetrahedralize import tetrahedralize

    command = "volviz bench unstructured " + " ".join(shlex.quote(a) for a in (argv if argv is not None
                                                                             else sys.argv[1:]))
    path = Path(args.out) / "unstructured.md"
    text = path.read_text() if path.exists() else "# Unstructured volume rendering benchmark (Blunt Fin)\n"
    ds = Path(args.dataset)
    grid = read_plot3d(ds / "bluntfinxyz.bin", ds / "bluntfinq.bin")
    mesh = tetrahedralize(grid, "Density")
    tf = bluntfin_tf()
    cams = camera_path(mesh.points, max(args.frames, 2))[:2]
    results: dict[str, Any] = {"command": command}
    if "sort" in args.only:
        load = os.getloadavg()[0]
        rows = sort_scan(mesh, cams, args.sort_sizes, args.reps)
        ib = index_buffer_row(mesh, tf, cams, args.reps)
        results["sort_scan"], results["index_buffer"] = rows, ib
        note = _run_note(command, load)
        text = splice(text, SORT_HEAD, [note, *_sort_scan_lines(rows, mesh.n_cells), "",
                                        *_index_buffer_lines(ib, mesh.n_cells, "the Blunt Fin")])
    if "cpu" in args.only:
        load = os.getloadavg()[0]
        results["cpu_side"] = cpu_side_scan(mesh, tf, cams, [(64, 64), *args.cpu_sizes], args.gl_lookup, args.reps)
        text = splice(text, CPU_HEAD, [_run_note(command, load), *_cpu_side_lines(results["cpu_side"],
                                                                                  mesh.n_cells)])
    if "large" in args.only:
        load = os.getloadavg()[0]
        big = large_mesh_row(refined_bluntfin(grid, args.large_refine), tf, cams, args.reps)
        big["refine"] = args.large_refine
        results["large"] = big
        text = splice(text, LARGE_HEAD, [_run_note(command, load), *_large_mesh_lines(big)])
    if "exact" in args.only:
        load = os.getloadavg()[0]
        results["exact"] = exact_rows(mesh, tf, cams[0], args.exact, args.gl_lookup)
        text = splice(text, EXACT_HEAD, [_run_note(command, load), *_exact_lines(results["exact"])])
    atomic_write_text(path, text)
    if args.json:
        atomic_write_text(Path(args.json), json.dumps(results, indent=2))
    print(f"wrote {path}")
    return 0


def _run_note(command: str, load: float) -> str:
    return (f"{RUN_NOTE} of their own, spliced into this report: `{command}`, "
            f"{time.strftime('%Y-%m-%d %H:%M')} UTC, 1-minute load average {load:.1f} at its start and "
            f"{os.getloadavg()[0]:.1f} at its end on the 2 shared cores.)")


#: the first words of the report's blocks ``--only`` replaces
SORT_HEAD, LARGE_HEAD = "Sort seconds against window size", "Large mesh:"
CPU_HEAD = "The CPU side of a pt-gl frame for a new camera"
EXACT_HEAD = "Against the exact float64 reference at the window's size"
#: paragraphs that belong to a block (besides its table rows and blank lines)
RUN_NOTE = "(The rows below come from a run"       # a block's first line when a run of its own made it
_BLOCK_TAILS = ("Drawn at ", "The order as the GPU pass's index buffer", RUN_NOTE, "The CPU side against its cost")


def splice(text: str, head: str, block: list[str]) -> str:
    """``text`` with the block that starts at the line beginning with ``head`` (or at the run note just before it)
    replaced by ``block``: the block runs on over blank lines, table rows and its own paragraphs
    (``_BLOCK_TAILS``). Without such a block, ``block`` goes before the speed-up line (or at the end)."""
    lines = text.split("\n")
    block = [ln for ln in block]
    while block and block[0] == "":
        block.pop(0)
    start = next((i for i, ln in enumerate(lines) if ln.startswith(head)), None)
    if start is None:
        at = next((i for i, ln in enumerate(lines) if ln.startswith("Speed-up of pt")), len(lines))
        return "\n".join(lines[:at] + block + [""] + lines[at:])
    end = start + 1
    if start >= 2 and lines[start - 2].startswith(RUN_NOTE):
        start -= 2
    while end < len(lines) and (lines[end] == "" or lines[end].startswith("|")
                                or (lines[end].startswith(_BLOCK_TAILS) and not lines[end].startswith(head))):
        if lines[end].startswith(RUN_NOTE):
            break                                   # the next block's run note
        end += 1
    while end > start + 1 and lines[end - 1] == "":
        end -= 1
    return "\n".join(lines[:start] + block + lines[end:])


def timed_sort(topo: Any, cam: Any, size: tuple[int, int], method: str = "mpvo", nonconvex: str = "auto"
               ) -> tuple[Any, float, float]:
    """``visibility_order`` with its wall seconds and the process CPU seconds it took (all threads; less sensitive
    than wall time to the other jobs on the shared cores)."""
    # the kernels (Numba) of this case only: a bench loads what its cases run
    from volviz.unstructured.sort import visibility_order

    t0, c0 = time.perf_counter(), time.process_time()
    res = visibility_order(topo, cam, size, method, nonconvex)
    return res, time.perf_counter() - t0, time.process_time() - c0


def sort_scan(mesh: Any, cams: list[Any], sizes: list[tuple[int, int]], reps: int) -> list[dict[str, Any]]:
    """Seconds of ``visibility_order`` against window size for each of ``SORT_ROWS``: the medians (wall and process
    CPU) over ``cams`` x ``reps`` calls after a warm-up call (each call for a camera other than the previous one)."""
    # the kernels (Numba) of this case only: a bench loads what its cases run
    from volviz.unstructured.topology import topology

    topo = topology(mesh)
    rows = []
    for label, method, nonconvex in SORT_ROWS:
        row: dict[str, Any] = {"label": label, "seconds": {}, "cpu_seconds": {}}
        timed_sort(topo, cams[-1], sizes[0], method, nonconvex)
        for w, h in sizes:
            runs = [timed_sort(topo, cam, (w, h), method, nonconvex) for _ in range(reps) for cam in cams]
            row["seconds"][f"{w}x{h}"] = float(np.median([r[1] for r in runs]))
            row["cpu_seconds"][f"{w}x{h}"] = float(np.median([r[2] for r in runs]))
        rows.append(row)
        print(f"sort scan: {row}", flush=True)
    return rows


def _numpy_chain(order: np.ndarray, visible: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The index buffer as numpy made it before ``volviz.unstructured.index_buffer`` (the baseline of
    ``index_buffer_row``): the visible cells, then the 12 vertex ids of each."""
    # the kernels (Numba) of this case only: a bench loads what its cases run
    from volviz.unstructured.topology import FACES

    cells = order[visible[order]]
    return cells, ((4 * cells.astype(np.int32))[:, None] + FACES.reshape(1, 12).astype(np.int32)).reshape(-1)


def index_buffer_row(mesh: Any, tf: Any, cams: list[Any], reps: int) -> dict[str, Any]:
    """The order as the GPU pass's index buffer (zero-opacity cull and int32 connectivity) for each camera's mpvo
    order: ``IndexBuffer.fill`` (one Numba pass into buffers kept between frames) against the numpy chain; medians
    of wall and process CPU seconds over ``cams`` x ``reps`` after a warm-up, and the cells drawn."""
    # the kernels (Numba) of this case only: a bench loads what its cases run
    from volviz.unstructured.index_buffer import IndexBuffer
    from volviz.unstructured.sort import visibility_order
    from volviz.unstructured.topology import topology, visible_cells

    topo = topology(mesh)
    vis = visible_cells(mesh, tf.scalars, tf.extinction)
    orders = [visibility_order(topo, cam, (1920, 1080)).order for cam in cams]
    buf = IndexBuffer(topo.n_tets)
    row: dict[str, Any] = {"cells": int(vis.sum())}
    for name, fn in (("fill", buf.fill), ("numpy", _numpy_chain)):
        fn(orders[-1], vis)
        wall, cpu = [], []
        for _ in range(reps):
            for order in orders:
                t0, c0 = time.perf_counter(), time.process_time()
                fn(order, vis)
                wall.append(time.perf_counter() - t0)
                cpu.append(time.process_time() - c0)
        row[f"{name}_s"], row[f"{name}_cpu_s"] = float(np.median(wall)), float(np.median(cpu))
    print(f"index buffer ({topo.n_tets} cells): {row}", flush=True)
    return row


def refined_bluntfin(grid: Any, factor: float) -> Any:
    """The Blunt Fin's curvilinear grid resampled ``factor`` times finer along each axis (trilinear in the grid's
    index space, coordinates and Density alike), tetrahedralised: a large non-convex mesh made by a command."""
    # heavy: SciPy, only for this case
    from scipy.ndimage import map_coordinates

    from volviz.model.datasets import CurvilinearGrid
    from volviz.unstructured.tetrahedralize import tetrahedralize

    shape = grid.points.shape[:3]
    new = [int(round((s - 1) * factor)) + 1 for s in shape]
    at = np.stack(np.meshgrid(*[np.linspace(0, s - 1, n) for s, n in zip(shape, new)], indexing="ij"))
    pts = np.stack([map_coordinates(grid.points[..., c], at, order=1) for c in range(3)], axis=-1)
    dens = map_coordinates(grid.point_data["Density"], at, order=1)
    return tetrahedralize(CurvilinearGrid(pts, {"Density": dens}), "Density")


def write_vtu(mesh: Any, path: str) -> None:
    """``mesh`` (a TetMesh) as a VTK XML unstructured grid, written atomically (a temporary file beside it, then
    renamed)."""
    # optional: meshio (a reader plugin's dependency), only to write the files it reads
    import meshio

    from volviz.io.atomic import check_output_path, temp_name

    target = check_output_path(path)
    tmp = temp_name(target)
    try:
        meshio.write(tmp, meshio.Mesh(mesh.points, [("tetra", mesh.tets)], point_data={"Density": mesh.scalars}),
                     file_format="vtu")
        os.replace(tmp, target)
    finally:
        tmp.unlink(missing_ok=True)


def large_mesh_row(mesh: Any, tf: Any, cams: list[Any], reps: int, draw: int = 256) -> dict[str, Any]:
    """The large mesh: topology seconds (once); the mpvo sort for 1920x1080 (median over ``cams`` x ``reps`` after a
    warm-up, with its stages: boundary relations, face sides, Kahn); the CPU bytes per cell of the mesh and its sort
    topology, and of one sort's own arrays; a ``draw``² frame by pt-gl (``gl_pt_frames``, 3D table: frame seconds
    to the GPU's completion, sort included) against the CPU pt renderer's image of the same camera and table."""
    # the kernels (Numba) of this case only: a bench loads what its cases run
    from volviz.unstructured import mpvo
    from volviz.unstructured.boundary_pairs import inner_boundary
    from volviz.unstructured.render import render
    from volviz.unstructured.sort import visibility_order
    from volviz.unstructured.topology import topology

    t0 = time.perf_counter()
    topo = topology(mesh)
    _ = topo.neighbor
    topo_s = time.perf_counter() - t0
    visibility_order(topo, cams[-1], (1920, 1080))
    timed = [timed_sort(topo, cam, (1920, 1080)) for _ in range(reps) for cam in cams]
    runs = [r[0] for r in timed]
    arrays = [mesh.points, mesh.tets, mesh.scalars, topo.points, topo.tets, topo.face_n, topo.face_d, topo.centroid,
              topo.circ_center, topo.circ_r2, topo.neighbor, topo.back_face, mpvo.planes32(topo)]
    m = mesh.n_cells
    row: dict[str, Any] = {
        "n_tets": int(m), "topology_s": topo_s, "sort_s": float(np.median([r.seconds for r in runs])),
        "sort_min_s": float(min(r.seconds for r in runs)), "sort_cpu_s": float(np.median([r[2] for r in timed])),
        "cycles": int(max(r.cycles for r in runs)),
        "stages_s": {k: float(np.median([r.stages[k] for r in runs])) for k in runs[0].stages},
        "inner_faces": int(len(inner_boundary(topo))), "boundary_faces": int(len(topo.boundary)),
        "bytes_per_cell": sum(int(a.nbytes) for a in arrays) / m,
        # one sort's own arrays: the order, a state byte and an in-degree per cell, Kahn's stack
        "sort_bytes_per_cell": (runs[0].order.nbytes + m * (1 + 4 + runs[0].order.itemsize)) / m}
    print(f"large mesh sort: {row}", flush=True)
    row["index_buffer"] = index_buffer_row(mesh, tf, cams, reps)
    if not draw:
        return row
    size = (draw, draw)
    gl, gl_img = gl_pt_frames(mesh, tf, cams, size, 1, "3d")
    c0 = time.perf_counter()
    pt_img, st = render(mesh, tf, cams[0], size, "pt", lookup="3d", return_stats=True)
    row["draw"] = {"size": draw, "pt_gl_frame_s": gl["frame_s"], "pt_gl_sort_s": gl["sort_s"],
                   "pt_frame_s": time.perf_counter() - c0, "pt_sort_s": st.sort_s, "gl_renderer": gl["gl_renderer"],
                   "gpu_bytes_per_cell": gl["gpu_bytes_per_cell"], "order_texture": gl["order_texture"]}
    row["draw"]["rmse_rgb"], row["draw"]["max_rgb"] = _rgb_err(gl_img, pt_img)
    print(f"large mesh draw: {row['draw']}", flush=True)
    return row


def cpu_side_scan(mesh: Any, tf: Any, cams: list[Any], sizes: list[tuple[int, int]], lookup: str, reps: int = 1
                  ) -> list[dict[str, Any]]:
    """The CPU side of a pt-gl frame for a new camera at each window size (``gl_pt_frames`` with ``split``: sort,
    order, index buffer or order texture upload, draw submission; one pass over ``cams``). ``sizes`` starts with a
    small window (64²), whose one-cell submission is the draw call's CPU cost: at a larger window llvmpipe's
    one-cell frame also fills the window's full-screen passes (the float target's clear and resolve), GPU work that
    a GPU does off the CPU, reported apart (``passes_s``); the upload is the small window's too (the order's upload
    does not depend on the window, and at a large one it drowns in the difference of two seconds-long llvmpipe
    frames); ``cpu_side_s`` = sort + order (at each size) + that upload + that submission. With the order as a
    texture the upload is the texture upload call as the volume times it (``upload_s``; the frame difference,
    ``ibo_s``, is kept beside it); with VTK's index buffer it is that difference. ``reps`` passes over ``cams``
    per size (medians)."""
    rows: list[dict[str, Any]] = []
    for w, h in sizes:
        res, _ = gl_pt_frames(mesh, tf, cams, (w, h), reps, lookup, split=True)
        row = {"size": [w, h], **{k: res[k] for k in ("frame_s", "cpu_s", "sort_s", "order_s", "ibo_s",
                                                       "one_cell_s", "draw_work_s", "cpu_side_proper_s",
                                                       "order_texture")}}
        row["upload_s"] = res.get("upload_s", res["ibo_s"])
        base = rows[0] if rows else row
        row["passes_s"] = max(row["one_cell_s"] - base["one_cell_s"], 0.0)
        row["cpu_side_s"] = row["sort_s"] + row["order_s"] + base["upload_s"] + base["one_cell_s"]
        rows.append(row)
        print(f"cpu side {w}x{h}: {row}", flush=True)
    return rows


def interactive_rows(mesh: Any, tf: Any, cams: list[Any], sizes: list[tuple[int, int]], reps: int, lookup: str,
                     max_pixels: int | None = None) -> list[dict[str, Any]]:
    """pt-gl while the camera moves (``GLPTVolume.set_interactive``, ``volviz.render.reduced_fill``) against its
    full-resolution frames, one window per size, all open at once and taken in turn for each camera (so that a
    change in the machine's load falls on every size alike): after a warm-up of both (shader variants compiled),
    ``reps`` passes over ``cams``, each camera drawn three times in each window: interactive for the new camera
    (``drag_s``: sort, index buffer and the reduced draw, as a drag frame), full resolution (``still_s``: the same
    camera, the draw alone) and interactive again (``moving_s``: the reduced draw alone); every Render() ends with
    WaitForCompletion. The error of the interactive image against the full-resolution one (8-bit RGB over black):
    RMSE median over the cameras and the largest max."""
    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    from volviz.render.gl_pt import GLPTVolume

    views: list[tuple[Any, Any, dict[str, list[float]], list[tuple[float, float]]]] = []
    for size in sizes:
        pl = bench_plotter(size, "black")
        vol = GLPTVolume(pl, mesh, tf, lookup=lookup)
        if max_pixels is not None:
            vol.interactive_pixels = max_pixels
        pl.camera_set = True
        cams[0].apply_to(pl.renderer.GetActiveCamera())
        for on in (False, True):
            vol.set_interactive(on)
            render_window(pl).Render()
        views.append((pl, vol, {"drag_s": [], "still_s": [], "moving_s": []}, []))
    for _ in range(reps):
        for cam in cams[1:] + cams[:1] if len(cams) > 1 else cams * 2:
            for pl, vol, times, errors in views:
                ren_win = render_window(pl)
                cam.apply_to(pl.renderer.GetActiveCamera())
                imgs = []
                for key, on in (("drag_s", True), ("still_s", False), ("moving_s", True)):
                    vol.set_interactive(on)
                    t0 = time.perf_counter()
                    ren_win.Render()
                    finish(ren_win)
                    times[key].append(time.perf_counter() - t0)
                    if key != "drag_s":
                        imgs.append(screenshot_rgb(pl))
                errors.append((rmse(imgs[1], imgs[0]), max_abs(imgs[1], imgs[0])))
    rows = []
    for (w, h), (pl, vol, times, errors) in zip(sizes, views):
        row = {"size": [w, h], "drawn": list(vol.target_size or (0, 0)), "cap": int(vol.interactive_pixels),
               **{k: float(np.median(v)) for k, v in times.items()},
               "rmse": float(np.median([e[0] for e in errors])), "max": float(max(e[1] for e in errors)),
               "frames_timed": len(errors)}
        vol.remove()
        pl.close()
        rows.append(row)
        print(f"interactive {w}x{h}: {row}", flush=True)
    return rows


def _size_scan(mesh: Any, tf: Any, cams: list[Any], sizes: list[tuple[int, int]], gl_lookup: str, sort: str,
               lookup: str, reps: int = 1, raycast_grid: int = 0) -> list[dict[str, Any]]:
    """Seconds per frame against window size for pt (the CPU renderer; one frame per camera), pt-gl (each render
    for a new camera, and the same camera drawn again: the draw alone) and vtkProjectedTetrahedraMapper, and with
    ``raycast_grid`` VTK's GPU ray caster on the mesh resampled to that many points a side: the medians over
    ``cams`` and ``reps`` after a warm-up, every GPU frame timed to its completion."""
    # the kernels (Numba) of this case only: a bench loads what its cases run
    from volviz.unstructured.render import render

    rows = []
    image = _resampled_image(mesh, raycast_grid) if raycast_grid else None
    for w, h in sizes:
        render(mesh, tf, cams[0], (w, h), "pt", sort=sort, lookup=lookup)
        pt = [render(mesh, tf, cam, (w, h), "pt", sort=sort, lookup=lookup, return_stats=True)[1].total_s
              for cam in cams]
        gl, _ = gl_pt_frames(mesh, tf, cams, (w, h), reps, gl_lookup, same=True)
        row = {"size": [w, h], "pt_s": float(np.median(pt)), "pt_gl_s": gl["frame_s"], "pt_gl_draw_s": gl["draw_s"],
               "pt_gl_sort_s": gl["sort_s"]}
        _vtk_render(mesh, tf, cams[0], (w, h), "vtkProjectedTetrahedraMapper", 1)
        row["vtk_pt_s"] = float(np.median([t for cam in cams for t in
                                           _vtk_render(mesh, tf, cam, (w, h), "vtkProjectedTetrahedraMapper",
                                                       reps)[1]]))
        if image is not None:
            _vtk_render(mesh, tf, cams[0], (w, h), "vtkSmartVolumeMapper", 1, grid=image)
            row["vtk_gpu_ray_s"] = float(np.median([t for cam in cams for t in
                                                    _vtk_render(mesh, tf, cam, (w, h), "vtkSmartVolumeMapper",
                                                                reps, grid=image)[1]]))
            row["raycast_grid"] = raycast_grid
        rows.append(row)
        print(f"scan {w}x{h}: {row}", flush=True)
    return rows


def _resampled_image(mesh: Any, n: int) -> Any:
    """The mesh's point field resampled onto an n³ image over its bounds (PyVista's ``sample``): the input
    of the GPU ray caster peer, the way a user of VTK without an unstructured GPU mapper would draw it."""
    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    import pyvista as pv

    grid = mesh.to_pyvista()
    lo, hi = np.array(grid.bounds[0::2]), np.array(grid.bounds[1::2])
    image = pv.ImageData(dimensions=(n, n, n), spacing=tuple((hi - lo) / (n - 1)), origin=tuple(lo))
    sampled = image.sample(grid)
    sampled.set_active_scalars(grid.active_scalars_name)
    return sampled


def exact_rows(mesh: Any, tf: Any, cam: Any, sizes: list[tuple[int, int]], gl_lookup: str) -> list[dict[str, Any]]:
    """pt-gl and vtkProjectedTetrahedraMapper against the exact float64 reference at each window size (one camera;
    RGB over black, 8-bit units), with the reference's own seconds."""
    # the kernels (Numba) of this case only: a bench loads what its cases run
    from volviz.unstructured.render import render

    rows = []
    for w, h in sizes:
        t0 = time.perf_counter()
        ref = render(mesh, tf, cam, (w, h), "reference")
        ref_s = time.perf_counter() - t0
        _, gl_img = gl_pt_frames(mesh, tf, [cam], (w, h), 1, gl_lookup)
        vtk_img = _vtk_render(mesh, tf, cam, (w, h), "vtkProjectedTetrahedraMapper", 1)[0]
        e_gl, e_vtk = _rgb_err(gl_img, ref), _rgb_err(vtk_img, ref)
        row = {"size": [w, h], "reference_s": ref_s, "pt_gl_rmse": e_gl[0], "pt_gl_max": e_gl[1],
               "vtk_pt_rmse": e_vtk[0], "vtk_pt_max": e_vtk[1]}
        rows.append(row)
        print(f"exact {w}x{h}: {row}", flush=True)
    return rows


def _exact_lines(rows: list[dict[str, Any]] | None) -> list[str]:
    """The markdown of ``exact_rows``."""
    if not rows:
        return []
    lines = ["", f"{EXACT_HEAD} (frame 0; RGB over black, 8-bit units; "
             "target for pt-gl RMSE ≤ 1, max ≤ 4):", "",
             "| window | pt-gl RMSE | pt-gl max | vtkProjectedTetrahedraMapper RMSE | its max | reference s |",
             "|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['size'][0]}x{r['size'][1]} | {r['pt_gl_rmse']:.2f} | {r['pt_gl_max']:.2f} | "
                     f"{r['vtk_pt_rmse']:.2f} | {r['vtk_pt_max']:.2f} | {r['reference_s']:.1f} |")
    return lines


def _plots(results: dict[str, Any], images: dict[str, np.ndarray], ref: np.ndarray, out: Path) -> None:
    # optional: matplotlib (volviz[bench]), only for the figures
    from volviz.bench import pyplot

    plt = pyplot()


    fig, ax = plt.subplots(figsize=(6, 4))
    for name, r in results["methods"].items():
        if name == "reference":
            continue
        ax.scatter(r["frame_s"], max(r["rmse_rgb"], 1e-3), s=40)
        ax.annotate(name.replace("vtkUnstructuredGridVolume", "UG").replace("Mapper", ""),
                    (r["frame_s"], r["rmse_rgb"]),
                    fontsize=8)
    ax.set_xscale("log")
    ax.set_yscale("log")
    ax.set_xlabel("seconds per frame (median)")
    ax.set_ylabel("RMSE vs reference (8-bit, RGB)")
    ax.set_title(f"Blunt Fin {results['size']}², perspective")
    fig.tight_layout()
    fig.savefig(out / "unstructured_time_error.png", dpi=110)
    plt.close(fig)

    names = list(images)
    fig, axes = plt.subplots(2, len(names), figsize=(3.2 * len(names), 6.6))
    for i, name in enumerate(names):
        rgb = np.clip(images[name][..., :3], 0, 1)
        axes[0, i].imshow(rgb)
        axes[0, i].set_title(name.replace("vtkUnstructuredGridVolume", "UG"), fontsize=8)
        axes[1, i].imshow(error_heatmap(images[name][..., :3], ref[..., :3], gain=8.0))
        r = results["methods"][name]
        axes[1, i].set_title(f"x8 error: RMSE {r['rmse_rgb']:.2f}, max {r['max_rgb']:.1f}", fontsize=8)
        for a in axes[:, i]:
            a.axis("off")
    fig.tight_layout()
    fig.savefig(out / "unstructured_side_by_side.png", dpi=90)
    plt.close(fig)


def _markdown(results: dict[str, Any], path: Path) -> None:
    m = results["methods"]
    pt = m["pt"]
    lines = [
        "# Unstructured volume rendering benchmark (Blunt Fin)", "",
        f"Command: `{results['command']}`", "",
        f"Blunt Fin, Density, {results['n_tets']} tetrahedra ({results['n_degenerate']} zero-volume tetrahedra of the "
        f"5-split dropped), {results['size']}² pixels, perspective, {results['frames']} frames along a fixed orbit. "
        "Times are medians after a warm-up; the machine has 2 cores shared with other jobs, so absolute times vary "
        f"(1-minute load average {results.get('load_average_start', float('nan')):.1f} at the start, "
        f"{results.get('load_average_end', float('nan')):.1f} at the end of this run).",
        "Errors are against the exact float64 reference ray caster on frame 0, in 8-bit units of premultiplied "
        "color (VTK images are read back over black, i.e. premultiplied RGB).",
        "VTK gets the same κ and opacity a = ρ·unit_distance with ScalarOpacityUnitDistance = unit_distance = 1.", "",
        "| method | s/frame | sort s | project s | raster s | tets/s | RMSE | max |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, r in m.items():
        if name == "pt-gl":
            lines.append(f"| pt-gl ({r['lookup']} lookup, VTK OpenGL; {r['frames_timed']} timed; "
                         f"CPU {r['cpu_s']:.3f} s) | "
                         f"{r['frame_s']:.3f} | {r['sort_s']:.3f} | {r['order_s']:.3f} (order) | | "
                         f"{r['tets_per_s']:.3g} | "
                         f"{r['rmse_rgb']:.2f} | {r['max_rgb']:.2f} |")
        elif name.startswith("pt"):
            lines.append(f"| {name} ({r.get('lookup', '')} lookup; {r.get('boundary_relations', 0)} boundary "
                         f"relations, {r['cycles']} cycles; CPU {r.get('cpu_s', float('nan')):.3f} s) | "
                         f"{r['frame_s']:.3f} | {r['sort_s']:.3f} | {r['project_s']:.3f} | {r['raster_s']:.3f} | "
                         f"{r['tets_per_s']:.3g} | {r['rmse_rgb']:.2f} | {r['max_rgb']:.2f} |")
        elif name == "reference":
            lines.append(f"| reference (exact) | {r['frame_s']:.1f} | | | | | 0 | 0 |")
        else:
            lines.append(f"| {name} ({r['frames_timed']} timed) | {r['frame_s']:.3f} | | | | {r['tets_per_s']:.3g} | "
                         f"{r['rmse_rgb']:.2f} | {r['max_rgb']:.2f} |")
    lines += ["", f"pt RGBA error: RMSE {pt['rmse_rgba']:.2f}, max {pt['max_rgba']:.2f}. "
              f"Sorting throughput: {pt['sort_tets_per_s'] / 1e6:.2f} M tetrahedra/s "
              f"(MPVO + object-space boundary relations + zero-opacity culling). "
              f"Fragments per frame: {pt['fragments']}."]
    lines += ["", "pt rows: 'auto' picks the separable pre-integration (Roettger §9.1: exact opacity 1 - exp(-l ρ̂), "
              "color polynomial of degree 2 in l, 256² table) when the largest optical depth of one cell is ≤ 6, "
              "as here; pt-3d is the same renderer with the trilinear 3D table (128² x 64, 16 MB). CPU is the "
              "process CPU time of one frame summed over threads (less sensitive to other jobs than wall time)."]
    along = pt.get("path")
    if along:
        lines += ["", f"Along the camera path as a movie export renders it (frame i + 1 sorted in the background while "
                  f"frame i draws, `volviz.unstructured.prefetch`): **{along['frame_s']:.3f} s per frame**, of which "
                  f"{along['sort_wait_s']:.3f} s in the sort stage (the wait for the background order and the "
                  "zero-opacity filter). With both cores already busy rasterising, "
                  "the background sort takes its time from the raster: the order is ready, but the frame is not "
                  "faster than sorting in line."]
    cpu_ns = pt.get("cpu_s", float("nan")) / max(pt["fragments"], 1) * 1e9
    lines += ["", f"Where the time goes: every pixel of the Blunt Fin's footprint crosses about "
              f"{pt['fragments'] / max(pt.get('covered_px', 1), 1):.0f} cells ({pt.get('early_terminated_px', 0)} "
              f"pixels reach opacity 0.999, where early termination stops); {pt['fragments'] / 1e6:.1f} M fragments "
              f"per frame at {cpu_ns:.0f} ns of CPU time each (all stages, both cores). Each fragment clips its ray "
              "against 4 planes and interpolates 10 table channels bilinearly (40 loads); Numba does not vectorise "
              "the table gathers, so this is scalar code at roughly 200 instructions per fragment."]
    v64 = results.get("vtk_pt_64_s")
    vbest = min((v["frame_s"] for k, v in m.items() if k.startswith("vtk")), default=float("inf"))
    vpt = m.get("vtkProjectedTetrahedraMapper", {}).get("frame_s")
    gl = m.get("pt-gl")
    if gl:
        lines += ["", f"pt-gl (`volviz.render.gl_pt`, OpenGL renderer: {results.get('gl_renderer', '?')}): volviz's "
                  "pre-integrated PT drawn through VTK's OpenGL with its own shaders: static vertex and index "
                  "buffers and the cells' data as texels, per frame only the back-to-front order as a texture of cell "
                  "ids, the exact ray segment per fragment, a float32 target. Its error is "
                  "measured on the 8-bit screen (rounding alone: RMSE ~0.29, max 0.5). "
                  f"Per frame in a 64² window, where fill is negligible, in total: **{gl['cpu_side_s']:.3f} s** "
                  f"(CPU {gl['cpu_side_cpu_s']:.3f} s), which on llvmpipe includes the draw's vertex processing on "
                  "the CPU. The CPU-side cost proper, what stays on the CPU with a GPU: "
                  f"**{gl['cpu_side_proper_s']:.3f} s** = sort {gl['cpu_side_sort_s']:.3f} s + index buffer "
                  f"{gl['cpu_side_order_s']:.3f} s (the cell order as VTK cells, numpy) + "
                  f"{gl['cpu_side_ibo_s']:.3f} s (VTK's index buffer build and upload: the frame minus the same frame "
                  "drawn again without a new order, minus sort and order, in process CPU seconds) + "
                  f"{gl['cpu_side_one_cell_s']:.3f} s (a draw submission: the same frame with an index buffer of "
                  "one cell, drawn twice, the second timed: callbacks, uniforms, VTK's traversal, the driver's draw "
                  f"call); the full draw's vertex and fragment work, {gl['cpu_side_draw_work_s']:.3f} s (the "
                  "frame drawn again minus the one-cell frame), is what a GPU takes off the CPU"
                  + (f". vtkProjectedTetrahedraMapper: {v64:.3f} s per 64² frame (target ≤ 1/5: {v64 / 5:.3f} s; "
                     f"pt-gl's total {gl['cpu_side_s'] / v64:.2f}x, proper {gl['cpu_side_proper_s'] / v64:.2f}x of "
                     "it)." if v64 else ".")]
    lines += _cpu_side_lines(results.get("cpu_side"), results["n_tets"])
    lines += _interactive_lines(results.get("interactive"))
    lines += _sort_scan_lines(results.get("sort_scan"), results["n_tets"])
    if results.get("index_buffer"):
        lines += ["", *_index_buffer_lines(results["index_buffer"], results["n_tets"], "the Blunt Fin")]
    big = results.get("large")
    if big:
        lines += _large_mesh_lines(big)
    scan = results.get("scan")
    if scan:
        ray = any("vtk_gpu_ray_s" in r for r in scan)
        lines += ["", "Seconds per frame against window size (medians over 2 cameras; pt one frame each; the GPU "
                  "methods after a warm-up, each frame to the GPU's completion): pt-gl for a new camera (sort, order, "
                  "draw), its sort, and the same camera drawn again (the draw alone)"
                  + (f"; VTK's GPU ray caster (vtkSmartVolumeMapper in GPU mode) on the mesh resampled to an image of "
                     f"{scan[0].get('raycast_grid', '')}³ points" if ray else "") + ":", "",
                  "| window | pt | pt-gl new camera | of which sort | pt-gl same camera | vtkProjectedTetrahedraMapper "
                  "| pt-gl speed-up |" + (" vtkGPUVolumeRayCastMapper (resampled) |" if ray else ""),
                  "|---|---|---|---|---|---|---|" + ("---|" if ray else "")]
        for r in scan:
            row = (f"| {r['size'][0]}x{r['size'][1]} | {r['pt_s']:.3f} | {r['pt_gl_s']:.4f} | "
                   f"{r.get('pt_gl_sort_s', float('nan')):.4f} | {r.get('pt_gl_draw_s', float('nan')):.4f} | "
                   f"{r['vtk_pt_s']:.4f} | {r['vtk_pt_s'] / r['pt_gl_s']:.2f}x |")
            lines.append(row + (f" {r['vtk_gpu_ray_s']:.4f} |" if ray else ""))
    lines += _exact_lines(results.get("exact"))
    if v64 and vpt and results["size"] > 64 and not gl:
        lines += ["", f"vtkProjectedTetrahedraMapper takes {v64:.3f} s per frame in a 64² window (its CPU work "
                  f"without the {results['size']}² fill) and {vpt:.3f} s at {results['size']}²: drawing the same "
                  "fragments through llvmpipe "
                  f"costs it about {max(vpt - v64, 0.0):.2f} s with VTK's simple per-fragment shader. A shader path "
                  "through VTK's OpenGL with our table lookups would pay at least that fill, already more than a "
                  f"frame at 5x the fastest VTK mapper ({min(vpt, vbest) / 5:.2f} s), so it cannot reach the target "
                  "on this machine (no GPU); it was not built."]
    sp = results.get("speedup_vs_fastest_vtk")
    if sp:
        lines += ["", f"Speed-up of pt over the fastest VTK mapper in this run: **{sp:.2f}x** (target ≥ 5x)."]
    lines += ["", "Targets: pt ≥ 5x faster than the fastest VTK mapper, RMSE ≤ 1 and max ≤ 4 against the reference, "
              "sorting ≥ 2 M tetrahedra/s.", "",
              "![time vs error](unstructured_time_error.png)", "", "![side by side](unstructured_side_by_side.png)", ""]
    path.write_text("\n".join(lines))


def _large_mesh_lines(big: dict[str, Any]) -> list[str]:
    st = big.get("stages_s", {})
    lines = ["", f"Large mesh: the Blunt Fin refined {big['refine']:g}x per axis (`--large-refine`), "
             f"{big['n_tets']} tetrahedra, {big['inner_faces']} of {big['boundary_faces']} boundary faces off "
             f"the hull; topology {big['topology_s']:.1f} s once; mpvo sort for 1920x1080 "
             f"{big['sort_s']:.3f} s median ({big['sort_min_s']:.3f} s min, {big.get('cycles', 0)} cycles): "
             f"**{big['n_tets'] / big['sort_s'] / 1e6:.1f} M tetrahedra/s** (target ≥ 20)"
             + (f", process CPU {big['sort_cpu_s']:.3f} s median (both threads): "
                f"{big['n_tets'] / big['sort_cpu_s'] / 1e6:.1f} M tetrahedra per CPU second" if "sort_cpu_s" in big
                else "")
             + (f"; of which boundary relations {st['relations']:.3f} s, face sides {st['sides']:.3f} s, "
                f"Kahn {st['kahn']:.3f} s (medians)" if "relations" in st else "")
             + (f"; of which face sides {st['sides']:.3f} s with the boundary relations made beside them on a "
                f"second thread (then {st['relations_wait']:.3f} s of waiting for them), Kahn {st['kahn']:.3f} s "
                "(medians)" if "relations_wait" in st else "")
             + f". CPU memory of the mesh and its sort topology {big['bytes_per_cell']:.0f} bytes per cell (the "
             "float32 face planes of the face sides, 64, included)"
             + (f", plus {big['sort_bytes_per_cell']:.0f} per cell for a sort (its order, 4, and its state, "
                "in-degrees and stack, 9, kept for the next sort)" if "sort_bytes_per_cell" in big else "") + "."]
    if big.get("index_buffer"):
        lines += ["", *_index_buffer_lines(big["index_buffer"], big["n_tets"], "the large mesh")]
    d = big.get("draw")
    if d:
        lines += ["", f"Drawn at {d['size']}² (3D table): pt-gl {d['pt_gl_frame_s']:.2f} s per frame for a new "
                  f"camera to the GPU's completion (sort {d['pt_gl_sort_s']:.3f} s; {d['gl_renderer']}), the CPU pt "
                  f"renderer {d['pt_frame_s']:.2f} s; pt-gl against pt: RMSE {d['rmse_rgb']:.2f}, max "
                  f"{d['max_rgb']:.2f} (8-bit; bound RMSE ≤ 1, max ≤ 4)."
                  + (f" GPU memory of the mesh {d['gpu_bytes_per_cell']:.0f} bytes per cell ("
                     + ("the order as a texture: the vertex buffer's corners, the static index buffer, the cells' "
                        "texels and the order" if d.get("order_texture") else "vertex and index buffers")
                     + "; `GLPTVolume.gpu_bytes`)." if "gpu_bytes_per_cell" in d else "")]
    return lines


def _cpu_side_lines(rows: list[dict[str, Any]] | None, n_tets: int) -> list[str]:
    if not rows:
        return []
    texture = rows[0].get("order_texture", False)
    base = rows[0]
    lines = ["", "The CPU side of a pt-gl frame for a new camera against window size (2 cameras, --reps frames each, "
             "every timed Render() ending with WaitForCompletion; the order "
             + ("as a texture of cell ids read by the vertex shader, the index buffer static"
                if texture else "as VTK's index buffer") + "): the sort and the order (wall seconds of the volume's "
             "own timings), measured at each size; the upload (" + ("the order texture's upload call as the "
             "volume times it, wall seconds; the frame minus the same frame drawn again without a new order, minus "
             "sort and order, is in the last column: in process CPU seconds it is the difference of two llvmpipe "
             "frames, noise of several milliseconds" if texture else "the frame minus the same frame drawn again "
             "without a new order, minus sort and order: VTK's index buffer build and upload; process CPU seconds; at "
             "a large window it drowns in the difference of two seconds-long llvmpipe frames, shown in the last "
             "column") + ") and the draw submission (the same frame with "
             "one cell drawn, process CPU seconds), neither of which depends on the window, measured "
             f"in the {base['size'][0]}x{base['size'][1]} window, where llvmpipe's fill is nil: at larger windows "
             "llvmpipe's one-cell frame also fills the window's full-screen passes (the float target's clear and "
             "resolve), GPU work that a GPU does off the CPU, shown apart; the CPU side = sort + order + upload + "
             "submission. The draw work (the full frame minus the one-cell frame) is what a GPU takes off the CPU "
             f"({n_tets} tetrahedra; issue #29):", "",
             "| window | frame s (wall) | sort s | order s | upload s | submission s | CPU side | "
             "llvmpipe's full-screen passes s | draw work s | frame - same - sort - order here s |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        side = r.get("cpu_side_s", r["cpu_side_proper_s"])
        lines.append(f"| {r['size'][0]}x{r['size'][1]} | {r['frame_s']:.3f} | {r['sort_s']:.4f} | "
                     f"{r['order_s']:.4f} | {base.get('upload_s', base['ibo_s']):.4f} | {base['one_cell_s']:.4f} | "
                     f"**{side * 1e3:.1f} ms** | "
                     f"{r.get('passes_s', 0.0):.4f} | {r['draw_work_s']:.3f} | {r['ibo_s']:.4f} |")
    ref = next((r for r in rows if tuple(r["size"]) == (512, 512)), None)
    if ref is not None:
        at_512 = max(ref.get("cpu_side_s", 1.0), 1e-9)
        ratios = [f"{r['size'][0]}x{r['size'][1]} {r.get('cpu_side_s', 0.0) / at_512:.2f}x"
                  for r in rows if tuple(r["size"]) not in ((512, 512), tuple(base["size"]))]
        if ratios:
            lines += ["", "The CPU side against its cost at 512² (target ≤ 1.25x, and ≤ 16 ms at 1920x1080): "
                      + ", ".join(ratios) + "."]
    return lines


def _interactive_lines(rows: list[dict[str, Any]] | None) -> list[str]:
    if not rows:
        return []
    lines = ["", "pt-gl while the camera moves (issue #29): during an interaction the cells are drawn into a float "
             f"target of at most {rows[0]['cap']} pixels (the window's aspect kept) and upsampled bilinearly over the "
             "window; the frame after the camera stops is drawn at full resolution "
             "(`GLPTVolume.set_interactive`, `volviz.render.reduced_fill`). One window per size, all open at once "
             "and drawn in turn for each camera (a change of load falls on every size alike); 2 cameras x reps "
             "after a warm-up, each Render() ending with WaitForCompletion, wall seconds (medians): a drag frame for "
             "a new camera (sort, index buffer, reduced draw), then for the same camera the full-resolution draw and "
             "the reduced draw alone (the fill); the error of the interactive image against the full-resolution one "
             "(8-bit RGB, premultiplied over black; RMSE median over the cameras, max the largest):", "",
             "| window | drawn at | drag frame s | full-resolution draw s | interactive draw s | RMSE | max |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['size'][0]}x{r['size'][1]} | {r['drawn'][0]}x{r['drawn'][1]} | {r['drag_s']:.3f} | "
                     f"{r['still_s']:.3f} | {r['moving_s']:.3f} | {r['rmse']:.2f} | {r['max']:.1f} |")
    small = min(rows, key=lambda r: r["size"][0] * r["size"][1])
    big = max(rows, key=lambda r: r["size"][0] * r["size"][1])
    if big is not small:
        lines += ["", f"The interactive draw at {big['size'][0]}x{big['size'][1]} takes "
                  f"{big['moving_s'] / small['moving_s']:.2f}x the one at {small['size'][0]}x{small['size'][1]} "
                  "(target ≤ 1: the cells fill the same pixels; the window's full-screen passes, its clear and the "
                  f"resolve, still grow with the window) and {big['moving_s'] / big['still_s']:.2f}x its own "
                  "full-resolution draw."]
    return lines


def _sort_scan_lines(rows: list[dict[str, Any]] | None, n_tets: int) -> list[str]:
    if not rows:
        return []
    sizes = list(rows[0]["seconds"])
    cpu = all("cpu_seconds" in r for r in rows)
    lines = ["", f"{SORT_HEAD} ({n_tets} tetrahedra; `visibility_order`, median over 2 cameras "
             "x reps after a warm-up" + (", wall seconds with the process CPU seconds (all threads) in brackets"
                                         if cpu else "")
             + "; M tets/s at the largest size in the last column" + (", wall (CPU)" if cpu else "") + "):", "",
             "| sort | " + " | ".join(sizes) + " | M tets/s |", "|---|" + "---|" * (len(sizes) + 1)]
    for r in rows:
        sec, c = r["seconds"], r.get("cpu_seconds", {})
        rate = f"{n_tets / sec[sizes[-1]] / 1e6:.1f}" + (f" ({n_tets / c[sizes[-1]] / 1e6:.1f})" if cpu else "")
        lines.append(f"| {r['label']} | " + " | ".join(f"{sec[k]:.4f}" + (f" ({c[k]:.4f})" if cpu else "")
                                                       for k in sizes) + f" | {rate} |")
    return lines


def _index_buffer_lines(ib: dict[str, Any] | None, n_tets: int, what: str) -> list[str]:
    if not ib:
        return []
    return [f"The order as the GPU pass's index buffer for {what} ({n_tets} tetrahedra, {ib['cells']} of them "
            "drawn: zero-opacity cull and int32 connectivity of 4 triangles per cell; medians over 2 cameras x reps "
            f"after a warm-up): `volviz.unstructured.index_buffer.IndexBuffer.fill`, one Numba pass into buffers "
            f"kept between frames, {ib['fill_s'] * 1e3:.1f} ms wall ({ib['fill_cpu_s'] * 1e3:.1f} ms CPU), against "
            f"{ib['numpy_s'] * 1e3:.1f} ms ({ib['numpy_cpu_s'] * 1e3:.1f} ms CPU) for the numpy chain "
            "(`order[visible[order]]`, then 4 c + corner broadcast) it replaced. (`volviz.render.gl_pt` uses it with "
            "`order_texture=False`; by default the order is a texture of cell ids, filled by `fill_cells`.)"]


if __name__ == "__main__":
    raise SystemExit(main())
