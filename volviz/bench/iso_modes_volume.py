"""``volviz bench iso_modes_volume``: what the note's transparency modes cost a frame with a regular volume in the
scene, before and after they were made to composite with it in depth order (issue #28).

A regular volume (default neghip) and an isosurface of it (value 120, opacity 0.3) are built as ``volviz render``
builds them (``offscreen_scene``), then each mode is drawn in these ways, peers in the same run: the GPU passes as
``auto`` drew them on any OpenGL before (``GLIsoSurfaces`` with ``peel_with_volumes=False``: the 2/3/4-pass surfaces
under the whole volume, exact mode's over it), the CPU overlay over the whole scene (the CPU backend before: the
surfaces over the whole volume), for the 2/3/4-pass modes the overlay with the volume split at the nearest surface
drawn while the GUI thread waits (as ``begin`` drew it before the split moved off the GUI thread), and what the
scene controller draws now (2/3/4-pass: the CPU overlay with the volume split at the nearest surface, the volume in
front drawn in ``compute`` on a GL thread of its own, ``volviz.render.iso_volume_split``; exact: the GPU's surfaces
peeled with the volume, ``volviz.render.gl_iso``). A GPU frame is one draw of the window to the GPU's completion; a
CPU overlay's frame is its whole update (``begin``: the scene drawn and read back; ``compute``; ``finish``: the
window drawn with the overlay), its ``begin`` and its GUI thread's part (``begin`` and ``finish``; in the app
``compute`` runs in a worker) also shown alone. Median of ``--reps`` frames after a warm-up. Writes
docs/bench/iso_modes_with_volume.md.
"""
from __future__ import annotations

import time
from pathlib import Path
from typing import Any

import numpy as np

from volviz.bench.offscreen import finish, timed_renders
from volviz.bench.volume_peeling import bench_command, iso_session, iso_volume_parser, report_head, write_report
from volviz.iso.composite import MODES

#: (label, kind): the note's passes on the GPU as drawn before (exact mode peeled over the finished scene), the CPU
#: overlay without the volume split, the split with the volume in front drawn on the GUI thread (as before the
#: split moved to its own thread) and what the scene controller draws now
WAYS = (("GPU passes (before)", "gpu-before"), ("CPU overlay, unsplit (before)", "cpu-unsplit"),
        ("CPU overlay, volume split on the GUI thread (before)", "cpu-split-gui"), ("now", "now"))


class _Drawn:
    """A ``FrontVolume`` stand-in that hands ``compute`` the image the GUI thread drew in ``begin``."""

    def __init__(self, image: Any) -> None:
        self.image = image

    def render(self, scene: Any) -> Any:
        return self.image


def _frames(controller: Any, kind: str, reps: int) -> tuple[float, float | None, float | None, str]:
    """(median seconds of a frame, median seconds of the CPU overlay's ``begin`` and of its GUI-thread part, or None
    on the GPU, what drew it) after one warm-up."""
    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    from volviz.render.gl_iso import GLIsoSurfaces

    plotter = controller.plotter
    view = controller.iso_view
    window = plotter.ren_win
    if kind == "gpu-before":   # VTK's volume pass after the 2/3/4 passes; exact mode's layer over the finished frame
        meshes, mode = list(view.meshes), view.mode
        view.remove()
        controller.iso_view = None
        surfaces = GLIsoSurfaces(plotter, meshes, mode, peel_with_volumes=False)
        try:
            return float(np.median(timed_renders(window, reps + 1)[1:])), None, None, "GPU passes"
        finally:
            surfaces.remove()
    if view.backend == "gpu":  # now: exact mode peeled with the volume
        drawn = "GPU, peeled with the volume" if view.peels_volumes else "GPU passes"
        return float(np.median(timed_renders(window, reps + 1)[1:])), None, None, drawn
    view.split_volume = kind != "cpu-unsplit"
    own = view.front_volume
    frames, begins, gui = [], [], []
    for _ in range(reps + 1):
        t0 = time.perf_counter()
        request = view.begin()
        if kind == "cpu-split-gui" and request["front_scene"] is not None:   # the GUI thread waits for it
            view.front_volume = _Drawn(own.render(request["front_scene"]))
        t1 = time.perf_counter()
        result = view.compute(request)
        view.front_volume = own
        t2 = time.perf_counter()
        view.finish(request, *result)
        finish(window)
        t3 = time.perf_counter()
        frames.append(t3 - t0)
        begins.append(t1 - t0)
        gui.append((t1 - t0) + (t3 - t2))
    drawn = "CPU overlay, volume split off the GUI thread" if view.split_volume else "CPU overlay"
    return float(np.median(frames[1:])), float(np.median(begins[1:])), float(np.median(gui[1:])), drawn


def measure(volume: Path, size: tuple[int, int], reps: int, value: float, opacity: float,
            modes: list[str]) -> list[dict[str, Any]]:
    """Every mode of ``modes`` in the ``WAYS`` at one size, each in a fresh scene."""
    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    from volviz.render.backend import plotter_gl_info
    from volviz.render.export import close_scene, offscreen_scene
    from volviz.scene.datasets import load_datasets

    rows = []
    for mode in modes:
        for label, kind in WAYS:
            if kind == "cpu-split-gui" and mode == "exact":   # exact mode is not split: drawn on the GPU
                continue
            session = iso_session(volume, value, opacity, True)
            session.render.options.update(iso_mode=mode, backend="cpu" if kind == "cpu-unsplit" else "auto")
            plotter, controller = offscreen_scene(session, load_datasets(session, None), size)
            try:
                controller.build()
                frame_s, begin_s, gui_s, drawn = _frames(controller, kind, reps)
                gl = plotter_gl_info(plotter).renderer
            finally:
                close_scene(plotter, controller)
            way = f"now: {drawn}" if kind == "now" else label
            rows.append({"volume": volume.name, "size": f"{size[0]}x{size[1]}", "mode": mode, "way": way,
                         "ms": 1e3 * frame_s, "begin_ms": None if begin_s is None else 1e3 * begin_s,
                         "gui_ms": None if gui_s is None else 1e3 * gui_s, "gl": gl})
            begin = ("" if begin_s is None or gui_s is None
                     else f" (begin {1e3 * begin_s:.0f} ms, GUI thread {1e3 * gui_s:.0f} ms)")
            print(f"{volume.name} {size[0]}x{size[1]} {mode} {way}: {1e3 * frame_s:.0f} ms{begin}", flush=True)
    return rows


def report(rows: list[dict[str, Any]], command: str, value: float, opacity: float) -> str:
    lines = report_head("The note's isosurface modes with a regular volume: frame time before and after issue #28",
                        command, rows)
    lines += ["", f"Isosurface value {value:g}, opacity {opacity:g}; the volume drawn by the ray caster `auto` picks "
              "(the GPU's while peeled). Median of the timed frames after a warm-up (module docstring of "
              "`volviz.bench.iso_modes_volume`): a GPU frame is one draw of the window; a CPU overlay's frame its "
              "whole update, its `begin` (the scene drawn and read back; in the GUI-thread split also the volume in "
              "front of the surfaces) shown alone, and its GUI thread's part (`begin` and `finish`: the window drawn "
              "with the overlay; `compute` runs in a worker in the app).", "",
              "| volume | window | mode | drawn by | ms per frame | of which begin | of which GUI thread |",
              "|---|---|---|---|---|---|---|"]
    for r in rows:
        begin = "" if r["begin_ms"] is None else f"{r['begin_ms']:.0f}"
        gui = "" if r.get("gui_ms") is None else f"{r['gui_ms']:.0f}"
        lines.append(f"| {r['volume']} | {r['size']} | {r['mode']} | {r['way']} | {r['ms']:.0f} | {begin} | {gui} |")
    lines += ["", "Before, both drawings put the surfaces on the wrong side of the whole volume (the GPU passes are "
              "blended before VTK's volume pass: the volume over them; the GPU's exact mode and the CPU overlay went "
              "over the finished scene). Now, with a regular volume shown, the 2/3/4-pass modes are drawn by the CPU "
              "overlay with the volume split at the nearest surface (`volviz.render.iso_volume_split`, the volume "
              "in front drawn off the GUI thread) and exact "
              "mode on the GPU peeled with the volume (`volviz.render.gl_iso`); errors against the exact composite: "
              "tests/test_iso_modes_volume.py.", ""]
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
