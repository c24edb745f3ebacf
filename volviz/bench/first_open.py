"""Benchmark: the first image of every shared dataset as ``volviz render FILE -o x.png`` makes it (issue #30).

For each file a user would open in the data folder (one member of each numbered series, the OpenFOAM case as its
folder) it measures, in a fresh process each, the wall time of ``volviz render FILE -o x.png`` (1024x768) and the
share of the image's pixels that differ from the background. For every dataset drawn as a volume it also measures
the legibility of the automatic transfer function (``volviz.optics.auto_tf``), in this process:

- *visible footprint*: of the pixels the data covers (the same view rendered with an opaque transfer function),
  the share whose colour differs visibly from the background (CIE76 colour difference above ``VISIBLE_DE``);
- *object visible*: the same share of the object's footprint, the view with an opaque transfer function that is
  transparent over the histogram's background mode as ``volviz.optics.auto_tf.background_mode`` finds it for the
  first look (``object_transfer_function``): a volume with a large background (CT air, the empty space around a
  molecule) covers its whole box with the first, the object only a part of it;
- *mode contrast*: the colour difference between the two main modes of the data's histogram, each seen as a slab
  of its value as thick as the mean chord of the data's box over the background (``mode_contrast``).

A picture (PPM, JPEG) is drawn in its own colours, through no transfer function: its row says *picture* and has no
legibility measures.

Writes only its section of ``docs/first-open.md``, between ``BEGIN`` and ``END`` (``volviz.io.doc_section``: the
app's window table and the prose around are kept), or only prints with ``--no-write``. ``--profile N`` adds where
the time of the N slowest files goes (cProfile of an in-process render, by volviz module). ``--only`` measures some
files and keeps the other rows (and the profiles, unless it makes new ones). ``--legibility-only`` renders no
file in a fresh process: it keeps each row's time, drawn share and notes (and the profiles) from the report, so the
legibility columns can be measured again on a busy machine. ``--boundary-rule`` measures the
legibility of regular volumes drawn with the boundary transfer function (Kindlmann & Durkin 1998,
``volviz.optics.boundary``) in place of the first look's, for the comparison in ``docs/first-open.md``; it only prints.
"""
from __future__ import annotations

import cProfile
import os
import platform
import pstats
import re
import resource
import subprocess
import sys
import tempfile
import time
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Optional

import numpy as np

from volviz.argtypes import UsageParser
from volviz.io import ReadError
from volviz.io.doc_section import merge_rows, read_section
from volviz.io.doc_section import write_section as write_marked
from volviz.io.registry import spec_of
from volviz.model.stats import scalar_values
from volviz.optics import TransferFunction
from volviz.optics.auto_tf import BACKGROUND_FRACTION, MODE_WIDTH, background_mode, finite_sample, mean_chord
from volviz.optics.boundary import boundary_transfer_function, regular_fields
from volviz.scene.series import series_pattern

DEFAULT_DATA = Path(os.environ.get("VOLVIZ_DATA", Path(__file__).resolve().parents[2].parent / "shared" / "data"))
REPORT = Path(__file__).resolve().parents[2] / "docs" / "first-open.md"
BEGIN, END = "<!-- volviz bench first_open: begin -->", "<!-- volviz bench first_open: end -->"
COMMAND = "VOLVIZ_DATA=../shared/data .venv/bin/volviz bench first_open --profile 3"
REPEATS = 3                    # timed runs per file after one untimed warm-up run (median reported, slowest too)
SIZE = (1024, 768)
METRIC_SIZE = (320, 240)       # the legibility measures render smaller (they compare shares, not details)
VISIBLE_DE = 10.0              # CIE76 difference a viewer sees at a glance (2.3 is just noticeable)
DRAWN_DIFFERENCE = 24          # summed |RGB| difference from the background of a drawn pixel
TARGET_S = 5.0
PROFILE_HEAD = "Where the time goes for the slowest files"
MAX_MB = 100
#: a file's kept measures (``kept_timings``): wall seconds, CPU seconds, drawn share, note, slowest wall seconds
Timing = tuple[Optional[float], Optional[float], Optional[float], str, Optional[float]]


def opened_files(root: Path) -> list[Path]:
    """The files under ``root`` a user opens: every data file, one member (the first) of each numbered series, a
    folder that a reader opens whole (an OpenFOAM case) as itself; no README, no sidecar a header names."""
    found: list[Path] = []
    seen: set[str] = set()
    for folder, dirs, files in os.walk(root):
        dirs.sort()
        here = Path(folder)
        if here != root and (here / "case.foam").exists():
            try:
                spec_of(here)
                found.append(here)
                dirs.clear()
                continue
            except ReadError:
                pass
        for name in sorted(files, key=_natural):
            path = here / name
            sidecar = path.suffix.lower() == ".h5" and path.with_suffix(".xdmf").exists()   # XDMF heavy data
            if name.lower() == "readme.md" or path.suffix.lower() == ".raw" or name.endswith(".dat.h5") or sidecar:
                continue
            pattern = series_pattern(path)
            if pattern is not None:
                if pattern in seen:
                    continue
                seen.add(pattern)
            found.append(path)
    return found


def _natural(name: str) -> list[Any]:
    return [int(part) if part.isdigit() else part for part in re.split(r"(\d+)", name)]


def drawn_fraction(image: np.ndarray) -> float:
    """The share of ``image``'s pixels that differ from its background (its top-left pixel)."""
    image = np.asarray(image)[..., :3].astype(np.int32)
    return float((np.abs(image - image[0, 0]).sum(axis=2) > DRAWN_DIFFERENCE).mean())


def to_lab(rgb: np.ndarray) -> np.ndarray:
    """sRGB in [0, 1] (..., 3) to CIE L*a*b* (D65)."""
    rgb = np.asarray(rgb, dtype=np.float64)
    linear = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    xyz = linear @ np.array([[0.4124, 0.2126, 0.0193], [0.3576, 0.7152, 0.1192], [0.1805, 0.0722, 0.9505]])
    xyz = xyz / np.array([0.95047, 1.0, 1.08883])
    f = np.where(xyz > 0.008856, np.cbrt(xyz), 7.787 * xyz + 16.0 / 116.0)
    return np.stack([116.0 * f[..., 1] - 16.0, 500.0 * (f[..., 0] - f[..., 1]), 200.0 * (f[..., 1] - f[..., 2])],
                    axis=-1)


def color_difference(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """CIE76 colour difference of sRGB colours in [0, 1]."""
    return np.linalg.norm(to_lab(a) - to_lab(b), axis=-1)


def main_modes(values: np.ndarray, bins: int = 128) -> tuple[float, float]:
    """The values of the two main modes of ``values``' histogram: its tallest bin, and the tallest local maximum at
    least 1/8 of the range away from it (the second tallest bin when the histogram has one hump)."""
    counts, edges = np.histogram(values, bins=bins)
    centres = 0.5 * (edges[1:] + edges[:-1])
    first = int(np.argmax(counts))
    padded = np.concatenate([[-1], counts, [-1]])
    peaks = [i for i in range(bins) if padded[i + 1] >= padded[i] and padded[i + 1] >= padded[i + 2]
             and abs(i - first) >= bins // 8 and counts[i] > 0]
    if not peaks:
        peaks = [i for i in np.argsort(counts)[::-1] if i != first][:1]
    second = max(peaks, key=lambda i: counts[i])
    return float(centres[first]), float(centres[second])


def slab_color(tf: Any, value: float, chord: float, background: np.ndarray) -> np.ndarray:
    """The colour of a slab of ``value`` ``chord`` thick seen through ``tf`` over ``background`` (emission and
    absorption with the transfer function's color and extinction)."""
    colors, extinction = tf.evaluate(np.array([value]))
    color = np.clip(np.asarray(colors, dtype=np.float64).reshape(-1, 3)[0], 0.0, 1.0)
    alpha = 1.0 - float(np.exp(-float(np.asarray(extinction).reshape(-1)[0]) * chord))
    return alpha * color + (1.0 - alpha) * np.asarray(background, dtype=np.float64)


def mode_contrast(values: np.ndarray, tf: Any, chord: float, background: np.ndarray) -> float:
    """CIE76 difference between the slabs (``slab_color``) of the two main modes (``main_modes``) of ``values``."""
    a, b = main_modes(values)
    return float(color_difference(slab_color(tf, a, chord, background), slab_color(tf, b, chord, background)))


@dataclass
class FirstImage:
    """One file's first image: time, drawn share, how it is drawn, and the legibility measures of a volume."""

    name: str
    megabytes: float
    seconds: Optional[float] = None
    drawn: Optional[float] = None
    kind: str = ""
    visible: Optional[float] = None
    object_visible: Optional[float] = None
    contrast: Optional[float] = None
    note: str = ""
    cpu: Optional[float] = None         # CPU seconds (user + system) of the render's process and its reader child
    slowest: Optional[float] = None     # wall seconds of the slowest timed run
    profile: list[str] = field(default_factory=list)


def render_timed(path: Path, out: Path) -> tuple[float, float, int, str]:
    """Wall seconds, CPU seconds (user + system of the process and the children it waited for), exit status and
    last stderr line of ``volviz render PATH -o OUT`` in a fresh process."""
    def cpu() -> float:
        used = resource.getrusage(resource.RUSAGE_CHILDREN)
        return used.ru_utime + used.ru_stime

    start, cpu_start = time.perf_counter(), cpu()
    done = subprocess.run([str(Path(sys.executable).parent / "volviz"), "render", str(path), "-o", str(out), "--size",
                           f"{SIZE[0]}x{SIZE[1]}"], capture_output=True, text=True, timeout=600)
    seconds, cpu_seconds = time.perf_counter() - start, cpu() - cpu_start
    lines = [line for line in done.stderr.splitlines() if line.strip()]
    return seconds, cpu_seconds, done.returncode, lines[-1] if lines else ""


@dataclass
class Footprints:
    """Pixel masks of one volume's view (``legibility``): ``seen``, its colour differs from the background by more
    than ``VISIBLE_DE``; ``data``, drawn by an opaque transfer function over the whole range; ``object``, drawn by
    one that is transparent over the background mode (``object_transfer_function``). The scalar bar's strip is in
    neither footprint."""

    seen: np.ndarray
    data: np.ndarray
    object: np.ndarray

    @property
    def visible(self) -> float:
        """The share of the data's footprint that is seen (the *visible* column)."""
        return _share(self.seen, self.data)

    @property
    def object_visible(self) -> float:
        """The share of the object's footprint that is seen (the *object visible* column)."""
        return _share(self.seen, self.object)


def _share(seen: np.ndarray, footprint: np.ndarray) -> float:
    return float((seen & footprint).sum() / max(int(footprint.sum()), 1))


def object_transfer_function(lo: float, hi: float, chord: float, mode: Optional[tuple[float, float, float]],
                             name: str = "") -> Any:
    """White and opaque (optical depth 60 along ``chord``) over ``[lo, hi]``, transparent over the background mode
    ``mode`` (``volviz.optics.auto_tf.background_mode``'s (low edge, high edge, centre): its histogram bins, the
    values ``low <= v < high``, or up to ``hi`` when the mode ends the range); opaque everywhere without one. The
    steps are ``1e-6`` of the range wide, far below a histogram bin (1/256 of it). A region at ``hi`` itself is
    opaque (``volviz.render.vtk_tf.tf_to_vtk`` keeps VTK's top inclusive): a footprint has no holes there."""
    rho = 60.0 / chord
    if mode is None:
        return TransferFunction([lo, hi], [(1.0, 1.0, 1.0)] * 2, [rho] * 2, name=name)
    eps = 1e-6 * (hi - lo)
    low, high = max(mode[0], lo), mode[1]
    points = [(lo, rho), (low - eps, rho)] if low - eps > lo else []
    if high < hi:
        points += [(low, 0.0), (high - eps, 0.0), (high, rho), (hi, rho)]
    else:                  # the mode ends the range: transparent up to the top
        points += [(low, 0.0), (hi, 0.0)]
    stops, extinction = zip(*points)
    return TransferFunction(stops, [(1.0, 1.0, 1.0)] * len(stops), extinction, name=name)


def legibility(path: Path, boundary_rule: bool = False) -> tuple[str, Optional[Footprints], Optional[float]]:
    """How ``path`` (a data or session file) is drawn, and for a volume its footprints (``Footprints``) and mode
    contrast (see the module docstring); ``boundary_rule``: of a regular volume drawn with
    ``volviz.optics.boundary``'s transfer function instead."""
    # heavy: the rendering layer (render.export loads PyVista and VTK), only when legibility is measured
    from volviz.render.export import open_target, render_session
    from volviz.render.scene_builder import ensure_transfer_functions
    from volviz.render.vtk_scene import volume_grid
    from volviz.scene.datasets import component_dataset, drawn_as, load_datasets
    from volviz.scene.drawn_tf import component_transfer_function
    from volviz.scene.lod import is_lod

    session, session_file = open_target(path)
    comp = session.components[0]
    if comp.type != "volume" or comp.dataset is None:
        return comp.type, None, None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        datasets = load_datasets(session, session_file)
        kind = drawn_as(datasets[comp.dataset])
        if kind != "volume":
            return kind, None, None
        ensure_transfer_functions(session, datasets)
        tf = component_transfer_function(session, comp)
        if tf is None:         # a picture (PPM, JPEG) drawn in its own colours: no transfer function to measure
            return "picture", None, None
        session.render.options.update(axes=False, outline=False)   # the data alone (the box's outline is no data)
        tf_name = str(comp.transfer_function)
        dataset = component_dataset(comp, datasets)
        if is_lod(dataset):
            raise ValueError(f"{path}: legibility measures a volume decoded whole, not one at a level of detail")
        chord = mean_chord(volume_grid(dataset).bounds)
        raw = scalar_values(dataset)
        values = np.asarray(raw, dtype=np.float64).reshape(-1)
        values = values[np.isfinite(values)]
        grid = regular_fields(dataset) if boundary_rule else None
        if grid is not None:
            tf = boundary_transfer_function(values, chord, grid, tf_name)
            session.set_transfer_function(comp.id, tf)
        lo, hi = tf.range
        mode = background_mode(finite_sample(raw))         # the sample and the mode auto_transfer_function uses
        masks: list[np.ndarray] = []
        for shown in (tf, object_transfer_function(lo, hi, chord, None, tf_name),
                      object_transfer_function(lo, hi, chord, mode, tf_name) if mode is not None else None):
            if shown is None:      # no background mode: the object's footprint is the data's
                masks.append(masks[-1])
                continue
            session.set_transfer_function(comp.id, shown)
            masks.append(render_session(session, session_file, METRIC_SIZE, datasets=datasets))
    background = np.asarray(session.render.background, dtype=np.float64)
    image, data_image, object_image = masks
    seen = color_difference(image / 255.0, background) > VISIBLE_DE
    prints = Footprints(seen, _footprint(data_image), _footprint(object_image))
    return kind, prints, mode_contrast(values, tf, chord, background)


def _footprint(image: np.ndarray) -> np.ndarray:
    """The pixels an opaque white transfer function draws, less the scalar bar's strip (the right fifth)."""
    drawn = np.abs(image.astype(np.int32) - image[0, 0]).sum(axis=2) > DRAWN_DIFFERENCE
    drawn[:, int(0.8 * METRIC_SIZE[0]):] = False
    return drawn


def where_time_goes(path: Path, top: int = 6) -> list[str]:
    """The volviz functions (and VTK's render) that took the most cumulative time of an in-process render of
    ``path`` after imports: cProfile, top ``top`` by own module, as 'module.function s'."""
    # heavy: the rendering layer (render.export loads PyVista and VTK), only for a profiled render
    from volviz.render.export import open_target, render_session

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        session, _ = open_target(path)
        profiler = cProfile.Profile()
        profiler.enable()
        render_session(session, None, SIZE)
        profiler.disable()
    stats = pstats.Stats(profiler)
    rows = []
    for (filename, _, function), entry in stats.stats.items():  # type: ignore[attr-defined]
        cumulative = entry[3]
        if "/volviz/" in filename and not function.startswith("<"):
            module = filename.split("/volviz/")[-1].removesuffix(".py").replace("/", ".")
            rows.append((cumulative, f"{module}.{function}"))
    rows.sort(reverse=True)
    total = sum(entry[2] for entry in stats.stats.values())  # type: ignore[attr-defined]
    picked = [f"`{name}` {seconds:.2f} s" for seconds, name in rows[1:top + 1]]
    return [f"in-process render {total:.2f} s of own time"] + picked


def measure(root: Path, names: Optional[list[str]] = None, boundary_rule: bool = False,
            timings: Optional[dict[str, Timing]] = None, repeats: int = REPEATS) -> list[FirstImage]:
    """Every file of ``opened_files`` (or those named in ``names``, relative to ``root``) measured: one untimed
    warm-up render (the file and the compiled kernels' cache read from disk once), then the median wall and CPU
    seconds of ``repeats`` fresh processes and the slowest of them; legibility with the boundary rule where
    ``boundary_rule``; with ``timings`` (``kept_timings``: file -> seconds, CPU seconds, drawn share, note,
    slowest) each file's times, drawn share and note are taken from there instead of rendering it (legibility
    only)."""
    records = []
    with tempfile.TemporaryDirectory() as work:
        for path in opened_files(root):
            name = path.relative_to(root).as_posix()
            if names and name not in names:
                continue
            size = sum(p.stat().st_size for p in path.rglob("*") if p.is_file()) if path.is_dir() else \
                path.stat().st_size
            record = FirstImage(name, size / 1e6)
            if timings is not None:
                record.seconds, record.cpu, record.drawn, record.note, record.slowest = \
                    timings.get(name, (None, None, None, "", None))
            elif record.megabytes < MAX_MB:
                out = Path(work) / "x.png"
                runs = [render_timed(path, out) for _ in range(1 + max(repeats, 1))][1:]   # the first warms caches
                status, last = runs[-1][2], runs[-1][3]
                if status == 0:
                    # heavy: Pillow, loaded only to read a rendered image back
                    from PIL import Image

                    record.seconds = float(np.median([run[0] for run in runs]))
                    record.cpu = float(np.median([run[1] for run in runs]))
                    record.slowest = max(run[0] for run in runs)
                    record.drawn = drawn_fraction(np.asarray(Image.open(out).convert("RGB")))
                else:
                    record.note = last.removeprefix("volviz: error: ")
            if not record.note:
                try:
                    shown = legibility(path, boundary_rule)
                except Exception as exc:  # a measure that cannot be made is said, the row kept
                    record.note = f"legibility: {type(exc).__name__}: {exc}"
                else:
                    record.kind, prints, record.contrast = shown
                    if prints is not None:
                        record.visible, record.object_visible = prints.visible, prints.object_visible
            print(f"{name}: {record.seconds} s (slowest {record.slowest} s, CPU {record.cpu} s) drawn {record.drawn} "
                  f"{record.kind} "
                  f"visible {record.visible} object {record.object_visible} contrast {record.contrast} "
                  f"{record.note}", flush=True)
            records.append(record)
    return records


def _number(value: Optional[float], fmt: str) -> str:
    return "" if value is None else format(value, fmt)


def markdown(records: list[FirstImage], profiles: dict[str, list[str]], loads: Optional[tuple[str, str]] = None,
             repeats: int = REPEATS) -> str:
    """The section of ``docs/first-open.md`` this benchmark writes (without its markers); ``loads``: the machine's
    load averages at the run's start and end, said when given."""
    lines = ["## `volviz render`: time to the first image, and legibility of the automatic transfer "
             "function", "", "Regenerate (about 10 minutes):", "", "```", COMMAND, "```", "",
             f"The legibility columns alone, keeping each file's time, drawn share and notes (and the profiles) as "
             f"they are here: `{COMMAND.replace(' --profile 3', '')} --legibility-only`.", "",
             f"Each file is rendered by `volviz render FILE -o x.png` ({SIZE[0]}x{SIZE[1]}) in a fresh process, "
             f"once untimed (a warm-up: the file and the compiled kernels' cache come from disk), then {repeats} "
             "times: *first image* is the median of that command's wall times (start-up, imports, reading, the "
             "transfer function, the render, the PNG), *slowest* the longest of them; target under "
             f"{TARGET_S:g} s for files under {MAX_MB} MB. *CPU* is the median CPU time of "
             "that process and the reader child it waited for (user + system, all threads), which a machine loaded "
             "by other work inflates far less than the wall time. *Drawn* is the share of "
             "the image's pixels that differ from the background. For volumes, *visible* is the share of the data's "
             "footprint (the same view with an opaque transfer function) whose colour differs from the background "
             f"by more than ΔE {VISIBLE_DE:g} (CIE76). *Object visible* is the same share within the object's "
             "footprint: the view with an opaque transfer function that is transparent over the histogram's "
             "background mode, where the data differs from the dominant background. The background mode is the one "
             "`volviz.optics.auto_tf.background_mode` finds for the first look (the tallest bin of a 256-bin "
             "histogram of the values, followed down both flanks of the lightly smoothed histogram to the valleys, "
             f"when it spans at most {MODE_WIDTH:.1%} of the range and holds more than {BACKGROUND_FRACTION:.0%} "
             "of the values); its values are those of its bins (low edge ≤ v < high edge). Without such a mode the "
             "object's footprint is the data's and the two columns agree. *Contrast* is the ΔE between the two "
             "main modes of the histogram, each seen as a slab one mean chord thick (`volviz.bench.first_open`). "
             f"The legibility images are {METRIC_SIZE[0]}x{METRIC_SIZE[1]}, drawn without the axes and the box's "
             "outline (no data); the scalar bar's strip (the right fifth) is in no footprint. "
             "Measured on "
             f"{platform.machine()} with {os.cpu_count()} cores, Mesa llvmpipe, while other work ran"
             + (f"; load average (1, 5, 15 min) at the start {loads[0]}, at the end {loads[1]}." if loads else "."),
             "",
             "| file | MB | drawn as | first image | slowest | CPU | drawn | visible | object visible | contrast (ΔE) "
             "| notes |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in records:
        lines.append(f"| `{r.name}` | {r.megabytes:.1f} | {r.kind} | {_number(r.seconds, '.1f')}"
                     f"{' s' if r.seconds is not None else ''} | {_number(r.slowest, '.1f')}"
                     f"{' s' if r.slowest is not None else ''} | {_number(r.cpu, '.2f')}"
                     f"{' s' if r.cpu is not None else ''} | {_number(r.drawn, '.0%')} | "
                     f"{_number(r.visible, '.0%')} | {_number(r.object_visible, '.0%')} | "
                     f"{_number(r.contrast, '.0f')} | {r.note.replace('|', '/')} |")
    if profiles:
        lines += ["", PROFILE_HEAD + " (cProfile of the same render in one process, cumulative seconds of the "
                  "largest volviz calls):", ""]
        for name, rows in profiles.items():
            lines.append(f"- `{name}`: " + "; ".join(rows))
    return "\n".join(lines) + "\n"


def kept_timings(report: Path = REPORT) -> dict[str, Timing]:
    """File -> (seconds, CPU seconds, drawn share, note, slowest seconds) of the rows of ``report``'s section, read
    by its header's column names (*first image*, *CPU*, *drawn*, *notes*, *slowest*; a report without a column
    gives None): what a ``--legibility-only`` run keeps."""
    timings: dict[str, Timing] = {}
    columns: list[str] = []
    for line in read_section(report, BEGIN, END).splitlines():
        cells = [cell.strip() for cell in line.strip().strip("|").split("|")]
        if line.startswith("| file |"):
            columns = cells
        elif line.startswith("| `") and columns:
            row = dict(zip(columns, cells))
            seconds, cpu, drawn = row.get("first image", ""), row.get("CPU", ""), row.get("drawn", "")
            note, slowest = row.get("notes", ""), row.get("slowest", "")   # a legibility error is measured again
            timings[cells[0].strip("`")] = (float(seconds.removesuffix(" s")) if seconds else None,
                                            float(cpu.removesuffix(" s")) if cpu else None,
                                            float(drawn.removesuffix("%")) / 100.0 if drawn else None,
                                            "" if note.startswith("legibility:") else note,
                                            float(slowest.removesuffix(" s")) if slowest else None)
    return timings


def kept_rows(text: str, profiled: bool, order: list[str], report: Path = REPORT) -> str:
    """The section ``text`` of an ``--only`` run with the rows of the other files kept from ``report``'s section (in
    ``order``), and its "where the time goes" list when this run profiled none."""
    old = read_section(report, BEGIN, END)
    text = merge_rows(old, text, order)
    if not profiled and PROFILE_HEAD in old:
        text = text.rstrip("\n") + "\n\n" + old[old.index(PROFILE_HEAD):].strip("\n") + "\n"
    return text


def write_section(text: str, report: Path = REPORT) -> None:
    """Replace this benchmark's section of ``report`` (between ``BEGIN`` and ``END``) by ``text``, keeping the rest
    of the document (the app's window table, prose)."""
    write_marked(report, BEGIN, END, text)


def main(argv: Optional[list[str]] = None) -> int:
    parser = UsageParser(prog="volviz bench first_open", description=__doc__.split("\n")[0])
    parser.add_argument("--data", type=Path, default=DEFAULT_DATA, help="the data folder (default $VOLVIZ_DATA)")
    parser.add_argument("--only", nargs="*", default=None, help="only these files (relative to the data folder)")
    parser.add_argument("--repeats", type=int, default=REPEATS, help="timed runs per file after one untimed "
                        f"warm-up; the median is reported (default {REPEATS})")
    parser.add_argument("--profile", type=int, default=0, help="say where the time goes for the N slowest files")
    parser.add_argument("--no-write", action="store_true", help="print only; leave docs/first-open.md alone")
    parser.add_argument("--legibility-only", action="store_true", help="measure only the legibility columns; keep "
                        "each file's time, drawn share and notes (and the profiles) from docs/first-open.md")
    parser.add_argument("--boundary-rule", action="store_true", help="measure regular volumes' legibility with the "
                        "boundary transfer function (volviz.optics.boundary) instead; print only")
    args = parser.parse_args(argv)
    timings = kept_timings() if args.legibility_only else None
    load_start = ", ".join(f"{v:.1f}" for v in os.getloadavg())
    records = measure(args.data.resolve(), args.only, args.boundary_rule, timings, args.repeats)
    slowest = sorted((r for r in records if r.seconds is not None), key=lambda r: -float(r.seconds or 0))
    profiled = [] if args.legibility_only else slowest[:max(args.profile, 0)]
    profiles = {r.name: where_time_goes(args.data.resolve() / r.name) for r in profiled}
    text = markdown(records, profiles, (load_start, ", ".join(f"{v:.1f}" for v in os.getloadavg())), args.repeats)
    if args.only or args.legibility_only:
        text = kept_rows(text, bool(profiles), [p.relative_to(args.data.resolve()).as_posix()
                                                 for p in opened_files(args.data.resolve())])
    print(text)
    if not args.no_write and not args.boundary_rule:
        write_section(text)
    return 0
