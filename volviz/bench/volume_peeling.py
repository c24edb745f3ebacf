"""``volviz bench volume_peeling``: what depth-peeling a translucent isosurface with a regular volume
(``volviz.render.volume_peeling``) costs a frame on this machine's OpenGL, and how much of the surface shows.

A regular volume (default neghip) and an isosurface of it (value 120, opacity 0.3, VTK's own mode) are built as
``volviz render`` builds them (``offscreen_scene``), then drawn in five ways, peers in the same run: the volume by
VTK's CPU ray caster without and with the surface unpeeled (what ``auto`` drew on a software OpenGL before), by the
GPU ray caster without the surface, with it unpeeled and with it depth-peeled (what volviz draws now). Per way: the
median time of ``--reps`` draws after a warm-up, each ending with the GPU's completion, and the share of pixels the
surface changes by more than 3 levels (against the same ray caster without it). Writes docs/bench/volume_peeling.md.
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
from volviz.session import Component, DatasetRef, Session

REPO = Path(__file__).resolve().parents[2]
DEFAULT_DATA = Path(os.environ.get("VOLVIZ_DATA", REPO.parent / "shared" / "data"))
#: (ray caster, surface, peeled): the CPU caster with the surface unpeeled is what ``auto`` drew on a software OpenGL
#: before; the GPU caster with the surface peeled is what volviz draws now
WAYS = (("cpu", False, False), ("cpu", True, False), ("gpu", False, False), ("gpu", True, False), ("gpu", True, True))


def iso_session(volume: Path, value: float, opacity: float, surface: bool) -> Any:
    """A session of the regular volume ``volume`` and, when ``surface``, an isosurface of it (``value``,
    ``opacity``)."""
    comps = [Component("vol", "volume", "data")]
    if surface:
        comps.append(Component("iso", "isosurface", "data",
                               settings={"styles": [{"value": value, "opacity": opacity}]}))
    return Session(datasets=[DatasetRef("data", str(volume))], components=comps)


def _draw(volume: Path, size: tuple[int, int], way: tuple[str, bool, bool], reps: int, value: float,
          opacity: float) -> tuple[float, np.ndarray, bool, str]:
    """(median seconds of a draw, the image, whether peeling was on, the OpenGL renderer) for one way of drawing."""
    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    from volviz.render.backend import plotter_gl_info
    from volviz.render.export import close_scene, offscreen_scene
    from volviz.render.volume_peeling import peel_volumes, peeling_volumes
    from volviz.scene.datasets import load_datasets

    caster, surface, peel = way
    session = iso_session(volume, value, opacity, surface)
    session.render.options["backend"] = caster
    plotter, controller = offscreen_scene(session, load_datasets(session, None), size)
    try:
        controller.build()
        if not peel:
            peel_volumes(plotter, [], False)        # VTK's default order, the volume's own ray caster
        times = timed_renders(plotter.ren_win, reps + 1)[1:]
        image = np.asarray(plotter.screenshot(None, return_img=True), dtype=np.float64)[..., :3]
        return float(np.median(times)), image, peeling_volumes(plotter), plotter_gl_info(plotter).renderer
    finally:
        close_scene(plotter, controller)


def measure(volume: Path, size: tuple[int, int], reps: int, value: float, opacity: float) -> list[dict[str, Any]]:
    """The ``WAYS`` at one size, the surface's visible share against the same caster without it."""
    drawn = {way: _draw(volume, size, way, reps, value, opacity) for way in WAYS}
    rows = []
    for caster, surface, peel in WAYS:
        seconds, image, peeled, gl = drawn[(caster, surface, peel)]
        bare = drawn[(caster, False, False)][1]
        rows.append({"volume": volume.name, "size": f"{size[0]}x{size[1]}", "caster": caster, "surface": surface,
                     "peeled": peeled, "ms": 1e3 * seconds,
                     "shows": float((np.abs(image - bare).max(axis=2) > 3).mean()) if surface else None,
                     "gl": gl})
    return rows


def report_head(title: str, command: str, rows: list[dict[str, Any]]) -> list[str]:
    """A report's title and its command line with the load average at its end and the rows' OpenGL."""
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
    return [f"# {title}", "",
            f"Command: `{command}` (load average at the end {load:.1f}; OpenGL: {rows[0]['gl'] if rows else '?'})."]


def report(rows: list[dict[str, Any]], command: str, value: float, opacity: float) -> str:
    lines = report_head("A translucent isosurface inside a regular volume: depth peeling's cost", command, rows)
    lines += ["", f"Isosurface value {value:g}, opacity {opacity:g}, VTK's own mode. Median of the timed draws after a "
             "warm-up, each ending with `WaitForCompletion`. Shows: share of pixels the surface changes by more "
             "than 3 levels against the same ray caster without it.", "",
             "| volume | window | ray caster | surface | peeled | ms per frame | shows |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        shows = "" if r["shows"] is None else f"{100 * r['shows']:.2f} %"
        lines.append(f"| {r['volume']} | {r['size']} | {r['caster']} | {'yes' if r['surface'] else 'no'} | "
                     f"{'yes' if r['peeled'] else 'no'} | {r['ms']:.0f} | {shows} |")
    lines += ["", "The CPU ray caster with the surface is what `auto` drew on a software OpenGL before: the surface "
              "under the whole volume. volviz now draws the last row while VTK's own mode shows a translucent "
              "surface in a regular volume (`volviz.render.volume_peeling`).", ""]
    return "\n".join(lines)


def iso_volume_parser(name: str, doc: str, sizes: list[tuple[int, int]], out: str) -> UsageParser:
    """The arguments of ``volviz bench NAME`` for an isosurface in regular volumes (this bench's and
    ``volviz.bench.iso_modes_volume``'s): data, volumes, the surface's value and opacity, sizes, repeats, out."""
    ap = UsageParser(prog=f"volviz bench {name}", description=doc.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=DEFAULT_DATA, help="the shared data folder (volumes/ in it)")
    ap.add_argument("--volumes", nargs="+", default=["volumes/neghip.slc"],
                    help="regular volumes, relative to --data")
    ap.add_argument("--value", type=float, default=120.0, help="the isosurface's value (default 120)")
    ap.add_argument("--opacity", type=float, default=0.3, help="the isosurface's opacity (default 0.3)")
    shown = " ".join(f"{w}x{h}" for w, h in sizes)
    ap.add_argument("--sizes", type=image_size, nargs="+", default=sizes, help=f"window sizes WxH (default {shown})")
    ap.add_argument("--reps", type=int_in(1, 1000), default=5, help="timed draws per way, median (default 5)")
    ap.add_argument("--out", type=Path, default=REPO / "docs" / "bench" / out)
    return ap


def main(argv: list[str] | None = None) -> int:
    ap = iso_volume_parser("volume_peeling", __doc__ or "", [(512, 384), (1024, 768)], "volume_peeling.md")
    args = ap.parse_args(argv)
    rows = []
    for name in args.volumes:
        for size in args.sizes:
            for row in measure(args.data / name, tuple(size), args.reps, args.value, args.opacity):
                print(f"{row['volume']} {row['size']} {row['caster']} surface={row['surface']} "
                      f"peeled={row['peeled']}: {row['ms']:.0f} ms shows={row['shows']}", flush=True)
                rows.append(row)
    write_report(args.out, report(rows, bench_command("volume_peeling", argv), args.value, args.opacity))
    return 0


def bench_command(name: str, argv: list[str] | None) -> str:
    """The command line ``volviz bench NAME ARGS`` that a report names (``argv``: None for the process's own)."""
    args = argv if argv is not None else sys.argv[1:]
    return f"volviz bench {name} {' '.join(shlex.quote(a) for a in args)}".strip()


def write_report(out: Path, text: str) -> None:
    """Write a report atomically and say where."""
    atomic_write_text(out, text)
    print(f"wrote {out}")


if __name__ == "__main__":
    raise SystemExit(main())
