"""Measure what a new user sees first: every shared dataset opened in a real main window, timed to its first complete
image, with a screenshot of the whole window and a markdown table (``docs/first-open.md``). Run under Xvfb:

    xvfb-run -a -s "-screen 0 1600x1000x24" .venv/bin/python -m volviz_app.first_open docs/first-open

Each file opens in a fresh window (default layout, settings in a temporary folder) of ``WINDOW_SIZE``, through
``MainWindow.open_path`` as File > Open does. The time runs from that call until the scene is installed and its
view-dependent parts (PT volume images, terrain, LOD blocks) are drawn, i.e. until the progress bar goes away, plus
one render of the viewport; an open that fails stops the clock at its error dialog. All files are opened in one
process, so imports and Numba's compiled kernels are warm after the first open that needs them. Only files named in
``--only`` are opened when it is given (their rows are rewritten, the others kept from the existing table). Only
this tool's section of the markdown (between ``BEGIN`` and ``END``) is rewritten: ``volviz bench first_open``'s
section and the prose around them are kept.

The data comes from ../shared/data (or $VOLVIZ_DATA): the files a user would open (one member of each numbered
series, every file of ``ecosystem/``, the OpenFOAM case as its folder)."""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional

from .smoke import pump_events

WINDOW_SIZE = (1366, 768)
TIMEOUT_S = 300.0
NOTE_CHARS = 320         # an error dialog's text is cut there in the table (the screenshot shows all of it)
#: the markers of this tool's section of the markdown: it rewrites only what lies between them (``volviz bench
#: first_open`` owns another section of the same file)
BEGIN, END = "<!-- volviz_app.first_open: begin -->", "<!-- volviz_app.first_open: end -->"
COMMAND = 'xvfb-run -a -s "-screen 0 1600x1000x24" .venv/bin/python -m volviz_app.first_open docs/first-open'

#: what a user would open in ../shared/data, besides every entry of ecosystem/ (globbed entries in sorted order)
FILES = ("bluntfin/bluntfinxyz.bin", "bluntfin/bluntfinq.bin", "headsq/quarter.1", "volumes/*",
         "terrain/SainteHelens.dem", "yukon/Yukon.map.pgm", "yukon/Yukon.texmap.ppm", "yukon/Yukon.fogmap.pgm",
         "storm/Storm.pvm-t01", "sky/SkyDome.ppm", "sky/clouds.jpeg", "series/warping_spheres.vtkhdf",
         "ecosystem/*")


@dataclass
class FirstOpen:
    """One dataset's first open: what the window showed and how long it took."""

    path: Path
    name: str                          # relative to the data folder
    format: str = ""
    kind: str = ""
    dimensions: str = ""
    array: str = ""
    seconds: Optional[float] = None    # to the first complete image (or to the error dialog)
    screenshot: str = ""
    notes: list[str] = field(default_factory=list)


def data_root() -> Path:
    env = os.environ.get("VOLVIZ_DATA")
    return Path(env).resolve() if env else Path(__file__).resolve().parent.parent.parent / "shared" / "data"


def dataset_paths(root: Path) -> list[Path]:
    """The files (and the OpenFOAM case folder) of ``FILES`` under ``root``, in table order."""
    out: list[Path] = []
    for pattern in FILES:
        out += sorted(root.glob(pattern)) if "*" in pattern else [root / pattern]
    return [p for p in out if p.exists() and p.name.lower() != "readme.md"]


def _format(window: Any, opened: Path) -> str:
    """The reader of each dataset (of a numbered series: its members' reader, that of the file opened)."""
    from volviz.io.registry import format_of

    names = []
    for ref in window.session.datasets:
        try:
            names.append(format_of(ref.path, ref.options))
        except Exception:  # a series pattern names no file
            names.append(format_of(opened, {}) + " series")
    return ", ".join(names)


def _kind(window: Any) -> str:
    """How each visible component is drawn: ``volume (PT)``, ``volume (VTK ray cast)``, ``volume (surface)``,
    ``terrain (natural scene)`` ..."""
    from volviz.render.scene_builder import uses_pt
    from volviz.scene.datasets import component_dataset
    from volviz.model import TimeSeries
    from volviz.scene.lod import is_lod
    from volviz.render.vtk_scene import is_surface

    controller = window.controller
    kinds = []
    for comp in window.session.components:
        if not comp.visible:
            continue
        how = ""
        if comp.type in ("terrain", "sky", "fog", "clouds"):
            how = "natural scene"
        elif comp.dataset is not None:
            dataset = component_dataset(comp, controller.datasets)
            how = ("LOD" if is_lod(dataset) else "PT" if uses_pt(dataset)
                   else "surface" if is_surface(dataset) else "VTK")
            if isinstance(dataset, TimeSeries):
                how += f", {len(dataset)} steps"
        kinds.append(f"{comp.type} ({how})" if how else comp.type)
    return "; ".join(kinds)


def _dimensions(window: Any) -> str:
    out = []
    for dataset in window.datasets.values():
        dataset = dataset.frame(0) if type(dataset).__name__ == "TimeSeries" else dataset
        dims = getattr(dataset, "dimensions", None)
        cells = getattr(dataset, "n_cells", None)
        text = " x ".join(str(d) for d in dims) if dims else type(dataset).__name__
        if type(dataset).__name__ in ("UnstructuredMesh", "TetMesh") and cells:
            text = f"{getattr(dataset, 'n_points', 0):,} points, {cells:,} cells"
        out.append(text)
    return "; ".join(out)


def _shown_array(window: Any) -> str:
    from volviz.render.decorations import scalar_bar_title

    return scalar_bar_title(window.plotter) or ""


def _describe(window: Any, record: FirstOpen) -> None:
    """Fill ``record`` from the window's shown scene (or its error dialog)."""
    if window.error_dialog is not None:
        text = " ".join(window.error_dialog.text().split())
        record.notes.append("error dialog: " + (text if len(text) <= NOTE_CHARS else text[:NOTE_CHARS] + " …"))
    if window.raw_dialog is not None:
        record.notes.append(f"headerless data: the layout dialog opens with the guess "
                            f"{window.raw_dialog.describe(window.raw_dialog.layout())}")
    if window.controller is None:
        return
    steps = ((lambda w: _format(w, record.path), "format"), (_kind, "kind"), (_dimensions, "dimensions"),
             (_shown_array, "array"))
    for step, attr in steps:
        try:
            setattr(record, attr, step(window))
        except Exception as exc:  # a description the table cannot give: say so, keep the row
            record.notes.append(f"({attr}: {type(exc).__name__}: {exc})")
    if window.nonfinite.note:
        record.notes.append(window.nonfinite.note)
    status = window.status_label.text()
    if not status.startswith("Showing"):
        record.notes.append(f"status bar: {status}")


def open_one(app: Any, path: Path, root: Path, out: Path, workdir: Path) -> FirstOpen:
    """Open ``path`` in a fresh window, time it to the first complete image, grab the window into ``out``."""
    from PySide6.QtCore import QSettings

    from .window import MainWindow

    record = FirstOpen(path, path.relative_to(root).as_posix())
    settings = QSettings(str(workdir / f"{path.name}.ini"), QSettings.Format.IniFormat)
    window = MainWindow(settings=settings, recovery_dir=workdir / "recovery")
    window.resize(*WINDOW_SIZE)
    window.show()
    window.layout_keeper.arrange()
    pump_events(app, lambda: window.isVisible() and window.plotter.interactor.isVisible(), 10.0)
    for _ in range(20):  # the first show's layout and initial render settle before the clock starts
        app.processEvents()
        time.sleep(0.01)

    start = time.perf_counter()
    window.open_path(path)
    done = pump_events(app, lambda: window.error_dialog is not None or window.raw_dialog is not None or (
        window.controller is not None and not window.progress_bar.isVisible()), TIMEOUT_S)
    if window.error_dialog is None and window.raw_dialog is None and done:
        window.plotter.render()
    record.seconds = time.perf_counter() - start
    if not done:
        record.notes.append(f"not shown after {TIMEOUT_S:.0f} s")
    pump_events(app, lambda: False, 0.3)  # the status bar's non-finite note, repaints
    _describe(window, record)
    shot = out / (_slug(record.name) + ".png")
    grab(window).save(str(shot))
    save_small_png(shot)
    record.screenshot = shot.name
    window.dirty = False
    for dialog in (window.error_dialog, window.raw_dialog):
        if dialog is not None:
            dialog.close()
    window.close()
    window.deleteLater()
    pump_events(app, lambda: False, 0.1)
    return record


def grab(window: Any) -> Any:
    """The window as the user sees it: its own grab with an open error dialog drawn over it where it stands."""
    from PySide6.QtCore import QPoint
    from PySide6.QtGui import QPainter

    pixmap = window.grab()
    dialog = window.error_dialog
    if dialog is not None and dialog.isVisible():
        painter = QPainter(pixmap)
        painter.drawPixmap(dialog.mapToGlobal(QPoint(0, 0)) - window.mapToGlobal(QPoint(0, 0)), dialog.grab())
        painter.end()
    return pixmap


def _slug(name: str) -> str:
    return "".join(c if c.isalnum() or c in "-_." else "_" for c in name.replace("/", "__"))


def save_small_png(path: Path, colors: int = 256) -> None:
    """Rewrite ``path`` as an 8-bit palette PNG (a window grab shrinks 3-5 times, legibly)."""
    from PIL import Image

    with Image.open(path) as image:
        small = image.convert("RGB").quantize(colors=colors, method=Image.Quantize.MEDIANCUT, dither=Image.Dither.NONE)
    small.save(path, optimize=True)


def _cell(text: str) -> str:
    return text.replace("|", "\\|").replace("\n", " ")


def markdown(records: list[FirstOpen], folder: str) -> str:
    """This tool's section of ``docs/first-open.md`` (without its markers): the table, with the command that
    regenerates it on top."""
    import platform

    lines = ["# The first open of every shared dataset", "",
             "Regenerate (under Xvfb; about 2 minutes):", "", "```", COMMAND, "```", "",
             f"Each file is opened in a fresh main window of {WINDOW_SIZE[0]}x{WINDOW_SIZE[1]} through "
             "`MainWindow.open_path` (what File > Open, drag-and-drop and the command line do). *First image* is the "
             "time from that call until the scene is installed and its view-dependent parts (PT volume images, "
             "terrain, LOD blocks) are drawn, plus one render of the viewport; for a failed open, until the error "
             "dialog. All files open in one process, so imports and Numba's compiled kernels are warm. Measured on "
             f"{platform.machine()} with {os.cpu_count()} cores, Mesa llvmpipe (no GPU), while other work ran on "
             "the machine: read the times as orders of magnitude.", "",
             "| file | format | kind (drawn as) | dimensions | shown array | first image | screenshot | notes |",
             "|---|---|---|---|---|---|---|---|"]
    for r in records:
        seconds = f"{r.seconds:.1f} s" if r.seconds is not None else ""
        shot = f"[png]({folder}/{r.screenshot})" if r.screenshot else ""
        lines.append("| " + " | ".join(_cell(v) for v in (f"`{r.name}`", r.format, r.kind, r.dimensions, r.array,
                                                         seconds, shot, "; ".join(r.notes))) + " |")
    return "\n".join(lines) + "\n"


def _kept_rows(md: Path) -> dict[str, str]:
    """The table rows of this tool's section of an existing ``md`` by file name (for ``--only``)."""
    from volviz.io.doc_section import read_section

    rows = {}
    for line in read_section(md, BEGIN, END).splitlines():
        if line.startswith("| `"):
            rows[line.split("`")[1]] = line
    return rows


def write_table(md: Path, records: list[FirstOpen], folder: str, order: Optional[list[str]] = None) -> None:
    """Write this tool's section of ``md`` (between ``BEGIN`` and ``END``; the rest of the file is kept). With
    ``order`` (the names of every file, in table order: an ``--only`` run) the rows of ``records`` replace theirs
    and the other rows are kept from the existing section."""
    from volviz.io.doc_section import write_section

    text = markdown(records, folder)
    if order is not None:
        lines = text.splitlines()
        head, rows = lines[:len(lines) - len(records)], lines[len(lines) - len(records):]
        rows_by_name = {**_kept_rows(md), **{r.name: line for r, line in zip(records, rows)}}
        text = "\n".join(head + [rows_by_name[n] for n in order if n in rows_by_name]) + "\n"
    write_section(md, BEGIN, END, text)


def main(argv: Optional[list[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m volviz_app.first_open", description=__doc__.split("\n")[0])
    parser.add_argument("out", nargs="?", default="docs/first-open", help="folder of the screenshots; the markdown "
                        "goes beside it as OUT.md")
    parser.add_argument("--only", nargs="*", default=None, help="open only these files (relative to the data folder)")
    args = parser.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    md = out.with_suffix(".md")
    root = data_root()

    from PySide6.QtWidgets import QApplication

    app = QApplication.instance() or QApplication([])
    paths = dataset_paths(root)
    if args.only:
        paths = [p for p in paths if p.relative_to(root).as_posix() in args.only]
    records = []
    with tempfile.TemporaryDirectory() as workdir:
        for path in paths:
            record = open_one(app, path, root, out, Path(workdir))
            print(f"{record.name}: {record.seconds:.1f} s {record.kind} {'; '.join(record.notes)}", flush=True)
            records.append(record)
    write_table(md, records, out.name, [p.relative_to(root).as_posix() for p in dataset_paths(root)]
                if args.only else None)
    print(f"wrote {md}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
