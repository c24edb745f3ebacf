"""``volviz bench multisampling``: what 4x multisampling costs a still frame, and what leaving it out changes in the
picture, on this machine's OpenGL.

Each session is built as ``volviz render`` builds it (``offscreen_scene``, views drawn), then the same frame is drawn
with the render window's multisampling at 4 and at 0: the median time of ``--reps`` draws after a warm-up, each
ending with the GPU's completion (``WaitForCompletion``), and the difference of the two images (RMSE and the share
of pixels off by more than 24, 8-bit units). The peer is the 4-sample frame. The app and ``volviz render`` draw
single-sampled on a software rasteriser (``volviz.render.image_overlay.single_sample_on_software``); this report is
the measurement behind that rule. Writes docs/bench/multisampling.md.
"""
from __future__ import annotations

import os
import shlex
import sys
from pathlib import Path
from typing import Any

import numpy as np

from volviz.argtypes import UsageParser, image_size, int_in
from volviz.bench.offscreen import timed_renders
from volviz.io.atomic import atomic_write_text

REPO = Path(__file__).resolve().parents[2]
SESSIONS = ("resources/sessions/yukon.json", "demo")   # (a PT volume draws single-sampled on any driver)


def _frame(plotter: Any, samples: int, reps: int) -> tuple[float, np.ndarray]:
    """The median seconds of ``reps`` draws with ``samples`` (after one warm-up draw) and the last image."""
    window = plotter.ren_win
    window.SetMultiSamples(samples)
    times = timed_renders(window, reps + 1)[1:]
    image = np.asarray(plotter.screenshot(None, return_img=True), dtype=np.float64)[..., :3]
    return float(np.median(times)), image


def measure(target: str, size: tuple[int, int], reps: int) -> dict[str, Any]:
    """One session at one window size: 4-sample and single-sample frame times and the image difference."""
    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    from volviz.render.backend import plotter_gl_info
    from volviz.render.export import close_scene, offscreen_scene, open_target
    from volviz.scene.datasets import load_datasets

    session, session_file = open_target(REPO / target if target.endswith(".json") else target)
    datasets = load_datasets(session, session_file)
    plotter, controller = offscreen_scene(session, datasets, size)
    try:
        controller.build()
        msaa_s, msaa = _frame(plotter, 4, reps)
        single_s, single = _frame(plotter, 0, reps)
        diff = np.abs(msaa - single)
        return {"session": target, "size": f"{size[0]}x{size[1]}", "gl": plotter_gl_info(plotter).renderer,
                "msaa4_ms": 1e3 * msaa_s, "single_ms": 1e3 * single_s, "ratio": msaa_s / max(single_s, 1e-9),
                "rmse": float(np.sqrt((diff ** 2).mean())), "off_24": float((diff.max(axis=2) > 24).mean())}
    finally:
        close_scene(plotter, controller)


def report(rows: list[dict[str, Any]], command: str) -> str:
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    lines = ["# Multisampling: cost of a still frame and its effect on the picture", "",
             f"Command: `{command}` (load average at the end {load:.1f}; OpenGL: {rows[0]['gl'] if rows else '?'}).",
             "", "Median of the timed draws after a warm-up, each ending with `WaitForCompletion`; the peer is the "
             "4-sample frame. Image difference: 8-bit units over RGB; off = share of pixels off by more than 24.", "",
             "| session | window | 4 samples ms | 1 sample ms | ratio | RMSE | off > 24 |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['session']} | {r['size']} | {r['msaa4_ms']:.1f} | {r['single_ms']:.1f} | "
                     f"{r['ratio']:.2f}x | {r['rmse']:.2f} | {100 * r['off_24']:.2f} % |")
    lines += ["", "The rule that follows (`single_sample_on_software`): no multisampling on a software rasteriser, "
              "where it multiplies the cost of every frame; a hardware driver keeps PyVista's 4 samples.", ""]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = UsageParser(prog="volviz bench multisampling", description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", type=image_size, nargs="+", default=[(1366, 768), (1920, 1080)],
                    help="window sizes WxH (default 1366x768 1920x1080)")
    ap.add_argument("--sessions", nargs="+", default=list(SESSIONS),
                    help="session files (relative to the repository) or demo / demo-volume")
    ap.add_argument("--reps", type=int_in(1, 1000), default=5, help="timed draws per frame, median (default 5)")
    ap.add_argument("--out", type=Path, default=REPO / "docs" / "bench" / "multisampling.md")
    args = ap.parse_args(argv)
    rows = []
    for target in args.sessions:
        for size in args.sizes:
            row = measure(target, tuple(size), args.reps)
            print(f"{row['session']} {row['size']}: 4 samples {row['msaa4_ms']:.1f} ms, 1 sample "
                  f"{row['single_ms']:.1f} ms ({row['ratio']:.2f}x), RMSE {row['rmse']:.2f}", flush=True)
            rows.append(row)
    command = "volviz bench multisampling " + " ".join(shlex.quote(a) for a in (argv if argv is not None
                                                                                else sys.argv[1:]))
    atomic_write_text(args.out, report(rows, command.strip()))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
