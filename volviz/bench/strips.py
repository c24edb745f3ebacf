"""``volviz bench strips``: a still frame drawn whole against the same frame drawn in strips
(``volviz.render.strips``, the app's slow still frames), at the window sizes people use.

Each session is built as ``volviz render`` builds it (``offscreen_scene``), then its still frame is drawn whole
(median of ``--reps`` draws after a warm-up, each to the GPU's completion) and in strips as the app draws them
(``strips_for(whole)`` at first, each strip sized to ``PASS_BUDGET_S`` at the rates of the frame before; or
``--strips`` of the same height), each pass timed to the GPU's completion; median over ``--reps`` frames of the
longest pass and of the sum. The peer is the whole frame; the image difference (RMSE and the share of pixels off
by more than 24, 8-bit units) says that the strips draw the same picture. Writes docs/bench/strips.md.
"""
from __future__ import annotations

import os
import shlex
import sys
import time
from pathlib import Path
from typing import Any

import numpy as np

from volviz.argtypes import UsageParser, image_size, int_in
from volviz.bench.offscreen import finish, render_window, timed_renders
from volviz.io.atomic import atomic_write_text
from volviz.render.strips import StripCosts, StripFrame

REPO = Path(__file__).resolve().parents[2]
DATA = Path(os.environ.get("VOLVIZ_DATA", REPO.parent / "shared" / "data"))
TARGETS = ("volumes/neghip.slc", "volumes/embryo.slc")   # regular volumes VTK draws (relative to the data folder)


def _image(plotter: Any) -> np.ndarray:
    return np.asarray(plotter.screenshot(None, return_img=True), dtype=np.float64)[..., :3]


def _striped(plotter: Any, strips: int, budget_s: float | None,
             profile: StripCosts | None = None) -> tuple[list[float], np.ndarray, StripCosts]:
    """The seconds of each pass of one frame in ``strips`` strips (at first, with ``budget_s``, planned from the
    ``profile`` of the frame before as the app does), its image and its strips' costs."""
    window = render_window(plotter)
    frame = StripFrame(window, plotter.renderer, strips, budget_s, profile)
    passes = []
    while not frame.done:
        t0 = time.perf_counter()
        frame.step()
        finish(window)
        passes.append(time.perf_counter() - t0)
    return passes, _image(plotter), frame.costs


def measure(target: str, size: tuple[int, int], reps: int, strips: int | None = None) -> dict[str, Any]:
    """One data file or session at one window size: the whole frame and the frame in strips (``strips`` of them,
    default the app's ``strips_for`` the whole frame's time)."""
    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    from volviz.render.backend import plotter_gl_info
    from volviz.render.export import close_scene, offscreen_scene, open_target
    from volviz.render.strips import PASS_BUDGET_S, strips_for
    from volviz.scene.datasets import load_datasets

    path = target if target in ("demo", "demo-volume") or Path(target).is_absolute() else str(DATA / target)
    session, session_file = open_target(path)
    datasets = load_datasets(session, session_file)
    plotter, controller = offscreen_scene(session, datasets, size)
    try:
        controller.build()
        window = render_window(plotter)
        window.SetDesiredUpdateRate(0.0001)   # the still rate
        whole_s = float(np.median(timed_renders(window, reps + 1)[1:]))
        whole = _image(plotter)
        budget = None if strips else PASS_BUDGET_S     # a number of strips given: all of the same height
        strips = strips or strips_for(whole_s)
        profile = None if budget is None else _striped(plotter, strips, budget)[2]   # warm-up
        frames = []
        for _ in range(reps):
            frames.append(_striped(plotter, strips, budget, profile))
            profile = None if budget is None else frames[-1][2]
        diff = np.abs(frames[-1][1] - whole)
        return {"target": target, "size": f"{size[0]}x{size[1]}", "gl": plotter_gl_info(plotter).renderer,
                "whole_ms": 1e3 * whole_s, "strips": strips, "passes": len(frames[-1][0]),
                "longest_ms": 1e3 * float(np.median([max(p) for p, _, _ in frames])),
                "sum_ms": 1e3 * float(np.median([sum(p) for p, _, _ in frames])),
                "last_pass_ms": 1e3 * float(np.median([p[-1] for p, _, _ in frames])),
                "rmse": float(np.sqrt((diff ** 2).mean())), "off_24": float((diff.max(axis=2) > 24).mean())}
    finally:
        close_scene(plotter, controller)


def report(rows: list[dict[str, Any]], command: str) -> str:
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    lines = ["# Still frames in strips: the longest pass against the whole frame", "",
             f"Command: `{command}` (load average at the end {load:.1f}; OpenGL: {rows[0]['gl'] if rows else '?'}).",
             "", "Whole: median of the timed still draws after a warm-up, each ending with `WaitForCompletion` (the "
             "peer). Strips: `strips_for(whole)` strips at first, each one sized to `PASS_BUDGET_S` at the rates of "
             "the frame before (the app's plan; the warm-up frame's later strips at the last one's rate), or "
             "`--strips` of one height, and a last pass for the 2D props and the axes; "
             "median over the frames of the longest pass, of the last pass (it swaps) and of all passes together, "
             "each pass to the GPU's completion. Image difference of the striped frame from the whole one: 8-bit "
             "units over RGB; off = share of pixels off by more than 24.", "",
             "| data | window | whole ms | strips at first | passes | longest pass ms | last pass ms | sum ms "
             "| longest / whole | RMSE | off > 24 |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['target']} | {r['size']} | {r['whole_ms']:.1f} | {r['strips']} | {r['passes']} | "
                     f"{r['longest_ms']:.1f} | {r['last_pass_ms']:.1f} | {r['sum_ms']:.1f} | "
                     f"{r['longest_ms'] / max(r['whole_ms'], 1e-9):.2f} | {r['rmse']:.2f} | "
                     f"{100 * r['off_24']:.2f} % |")
    lines.append("")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = UsageParser(prog="volviz bench strips", description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", type=image_size, nargs="+", default=[(990, 673), (1920, 1080), (3840, 2160)],
                    help="window sizes WxH (default 990x673, the app's viewport on a 1366x768 screen, 1920x1080 and "
                         "3840x2160)")
    ap.add_argument("--targets", nargs="+", default=list(TARGETS),
                    help="data files (relative to $VOLVIZ_DATA), session files or demo / demo-volume")
    ap.add_argument("--reps", type=int_in(1, 1000), default=3, help="timed frames, median (default 3)")
    ap.add_argument("--strips", type=int_in(1, 16), default=None,
                    help="strips per frame (default: as the app, strips_for the whole frame's time)")
    ap.add_argument("--out", type=Path, default=REPO / "docs" / "bench" / "strips.md")
    args = ap.parse_args(argv)
    rows = []
    for target in args.targets:
        for size in args.sizes:
            row = measure(target, tuple(size), args.reps, args.strips)
            print(f"{row['target']} {row['size']}: whole {row['whole_ms']:.1f} ms, {row['passes']} passes, longest "
                  f"{row['longest_ms']:.1f} ms, sum {row['sum_ms']:.1f} ms, RMSE {row['rmse']:.2f}", flush=True)
            rows.append(row)
    command = "volviz bench strips " + " ".join(shlex.quote(a) for a in (argv if argv is not None else sys.argv[1:]))
    atomic_write_text(args.out, report(rows, command.strip()))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
