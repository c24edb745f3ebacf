"""``volviz bench iso_modes_volume``: what the note's transparency modes cost a frame with a regular volume in the
scene, before and after the volume was split at the surfaces (issue #28, ``volviz.render.iso_volume_split``).

A regular volume (default neghip) and an isosurface of it (value 120, opacity 0.3) are built as ``volviz render``
builds them (``offscreen_scene``), then each mode is drawn in three ways, peers in the same run: the GPU passes
(``GLIsoView``, what ``auto`` drew on any OpenGL before: the surfaces under the whole volume), the CPU overlay over
the whole scene (the CPU backend before: the surfaces over the whole volume) and the CPU overlay with the volume
split (what volviz draws now on either backend). A GPU frame is one draw of the window to the GPU's completion; a CPU
overlay's frame is its whole update (``begin``: the scene drawn and read back, now with the volume in front of the
surfaces drawn once more; ``compute``; ``finish``: the window drawn with the overlay), its ``begin`` (GUI thread)
also shown alone. Median of ``--reps`` frames after a warm-up. Writes docs/bench/iso_modes_with_volume.md.
"""
from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np

from volviz.bench.offscreen import finish, timed_renders
from volviz.bench.volume_peeling import bench_command, iso_session, iso_volume_parser, report_head, write_report
from volviz.iso.composite import MODES

#: (label, the note's passes on the GPU, the CPU overlay's volume split)
WAYS = (("GPU passes (before)", True, False), ("CPU overlay, unsplit (before)", False, False),
        ("CPU overlay, volume split (now)", False, True))


def _frames(controller: Any, gpu: bool, split: bool, reps: int) -> tuple[float, float]:
    """(median seconds of a frame, median seconds of the CPU overlay's ``begin``; 0 on the GPU) after one warm-up."""
    from volviz.render.gl_iso import GLIsoView

    plotter = controller.plotter
    view = controller.iso_view
    window = plotter.ren_win
    if gpu:                  # the GPU passes as the controller made them before: VTK's volume pass after them
        meshes = list(view.meshes)
        view.remove()
        view = controller.iso_view = GLIsoView(plotter, meshes, mode=view.mode)
        return float(np.median(timed_renders(window, reps + 1)[1:])), 0.0
    view.split_volume = split
    frames, begins = [], []
    for _ in range(reps + 1):
        t0 = time.perf_counter()
        request = view.begin()
        t1 = time.perf_counter()
        view.finish(request, *view.compute(request))
        finish(window)
        frames.append(time.perf_counter() - t0)
        begins.append(t1 - t0)
    return float(np.median(frames[1:])), float(np.median(begins[1:]))


def measure(volume: Path, size: tuple[int, int], reps: int, value: float, opacity: float,
            modes: list[str]) -> list[dict[str, Any]]:
    """Every mode of ``modes`` in the ``WAYS`` at one size, each in a fresh scene."""
    from volviz.render.backend import plotter_gl_info
    from volviz.render.export import close_scene, offscreen_scene
    from volviz.scene.datasets import load_datasets

    rows = []
    for mode in modes:
        for label, gpu, split in WAYS:
            session = iso_session(volume, value, opacity, True)
            session.render.options.update(iso_mode=mode, backend="auto")
            plotter, controller = offscreen_scene(session, load_datasets(session, None), size)
            try:
                controller.build()
                frame_s, begin_s = _frames(controller, gpu, split, reps)
                gl = plotter_gl_info(plotter).renderer
            finally:
                close_scene(plotter, controller)
            rows.append({"volume": volume.name, "size": f"{size[0]}x{size[1]}", "mode": mode, "way": label,
                         "ms": 1e3 * frame_s, "begin_ms": 1e3 * begin_s if not gpu else None, "gl": gl})
            print(f"{volume.name} {size[0]}x{size[1]} {mode} {label}: {1e3 * frame_s:.0f} ms "
                  f"(begin {1e3 * begin_s:.0f} ms)", flush=True)
    return rows


def report(rows: list[dict[str, Any]], command: str, value: float, opacity: float) -> str:
    lines = report_head("The note's isosurface modes with a regular volume: frame time before and after the volume "
                        "split", command, rows)
    lines += ["", f"Isosurface value {value:g}, opacity {opacity:g}; the volume drawn by the ray caster `auto` picks. "
             "Median of the timed frames after a warm-up (module docstring of `volviz.bench.iso_modes_volume`): a "
             "GPU frame is one draw of the window; a CPU overlay's frame its whole update, its `begin` (the GUI "
             "thread's part: the scene drawn and read back, now also the volume in front of the surfaces) shown "
             "alone.", "",
             "| volume | window | mode | drawn by | ms per frame | of which begin |", "|---|---|---|---|---|---|"]
    for r in rows:
        begin = "" if r["begin_ms"] is None else f"{r['begin_ms']:.0f}"
        lines.append(f"| {r['volume']} | {r['size']} | {r['mode']} | {r['way']} | {r['ms']:.0f} | {begin} |")
    lines += ["", "Before, both drawings put the surfaces on the wrong side of the whole volume (the GPU passes are "
              "blended before VTK's volume pass: the volume over them; the CPU overlay went over the finished "
              "scene); with a regular volume shown volviz now draws every mode by the CPU overlay with the volume "
              "split (`volviz.render.iso_volume_split`; errors against the exact composite: "
              "tests/test_iso_modes_volume.py).", ""]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = iso_volume_parser("iso_modes_volume", __doc__ or "", [(512, 384)], "iso_modes_with_volume.md")
    ap.add_argument("--modes", nargs="+", choices=MODES, default=list(MODES), help="the note's modes (default all)")
    args = ap.parse_args(argv)
    rows = []
    for name in args.volumes:
        for size in args.sizes:
            rows += measure(args.data / name, tuple(size), args.reps, args.value, args.opacity, args.modes)
    write_report(args.out, report(rows, bench_command("iso_modes_volume", argv), args.value, args.opacity))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
