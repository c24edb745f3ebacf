"""The `volviz` command line: info, render, bench, compress. Never imports Qt.

User errors (unreadable files, bad sessions, bad arguments) print one line ``volviz: error: ...`` and exit 2; an
unexpected failure prints one line too (``--debug`` shows the traceback) and exits 1.
"""
from __future__ import annotations

import argparse
import atexit
import gc
import importlib
import json
import math
import os
import sys
import warnings
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Iterator, Optional, Sequence

import volviz
from volviz.argtypes import MAX_MOVIE_FRAMES, MAX_MOVIE_SECONDS, UsageError, UsageParser, float_in, image_size

#: the benchmarks of ``volviz bench NAME`` (module ``volviz.bench.NAME``) and what each measures
BENCHMARKS = {
    "tables": "pre-integration tables: build time and error against the exact ray integral",
    "unstructured": "projected tetrahedra on the Blunt Fin against VTK's unstructured volume mappers",
    "pt_order": "the GPU PT pass during a drag: the error of drawing with the visibility order of an earlier camera",
    "compression": "the wavelet codec against blosc2, zfp and wavelet + zstd (ratio, PSNR, speed)",
    "nature": "the natural scene (terrain, fog, clouds): frame time and error along a flight",
    "iso": "multiple semi-transparent isosurfaces: compositing modes against the exact order",
    "isolation": "crash-isolated reading: isolated against in-process read time on every shared dataset",
    "robustness": "fuzz campaign: mutated shared files through volviz's readers and VTK's, side by side",
    "first_open": "volviz render of every shared file: time to the first image, drawn share, transfer-function "
                  "legibility",
    "multisampling": "a still frame with 4x multisampling against one sample: time and image difference",
    "volume_peeling": "a translucent isosurface in a regular volume: depth peeling's frame time and the surface's "
                      "visible share",
    "startup": "fresh processes: volviz info / render and the app's first frame (wall time, peak memory, imports)",
    "iso_modes_volume": "the note's isosurface modes with a regular volume: frame time before and after the volume "
                        "split",
    "strips": "a slow still frame drawn in strips across event-loop turns, as the app does: the longest pass "
              "against the whole frame",
}
#: commands whose arguments go, unread here, to their own parser (``volviz.regular.cli``, ``volviz.bench.NAME``)
PASSED_ON = ("bench", "compress")
MOVIE_FPS = float_in(0.0, 240.0, low_open=True)


def _array_spec(text: str) -> str:
    """An argument type: an array spec ``NAME``, ``NAME:c`` or ``NAME:magnitude``, ``NAME@cells`` for the cell array
    of a name also on the points (``volviz.model.arrays``)."""
    # NumPy: only when --array is given (the parser stays light for --help)
    from volviz.model.arrays import parse_array_spec

    try:
        return str(parse_array_spec(text))
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _reader_option(text: str) -> tuple[str, Any]:
    """``KEY=VALUE`` -> (key, value): an integer, a number, true / false, or the text."""
    key, sep, value = text.partition("=")
    if not sep or not key.strip().isidentifier():
        raise argparse.ArgumentTypeError(f"{text!r} is not KEY=VALUE (e.g. dataset=/entry/data/data)")
    for kind in (int, float):
        try:
            return key.strip(), kind(value)
        except ValueError:
            pass
    return key.strip(), {"true": True, "false": False}.get(value.strip().lower(), value)


def _data_options(command: argparse.ArgumentParser) -> None:
    command.add_argument("--array", type=_array_spec, metavar="NAME[:c]",
                         help="the array to show: NAME, NAME:0.. (one component) or NAME:magnitude; "
                              "NAME@cells:... the cell array of a name also on the points")
    command.add_argument("--q", metavar="FILE", help="the PLOT3D solution (q) file of a PLOT3D grid file")
    command.add_argument("--option", type=_reader_option, action="append", default=[], metavar="KEY=VALUE",
                         help="an option of the file's reader (repeatable), e.g. dataset=/entry/data/data (HDF5), "
                              "variable=V (MATLAB), series=3 (DICOM), level=0 (OME-Zarr), time_index=2")


def build_parser() -> argparse.ArgumentParser:
    parser = UsageParser(prog="volviz", description="Accurate, fast volume rendering.")
    parser.add_argument("--version", action="version", version=f"volviz {volviz.__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks of unexpected errors")
    sub = parser.add_subparsers(dest="command", parser_class=UsageParser)

    info = sub.add_parser("info", help="describe a data file or a compressed volume, or the OpenGL in use",
                          description="Kind, dimensions, every array (association, components, range, non-finite "
                          "values), time steps and series membership of a data file, or a .vvz/.vvs file's header. "
                          "With --gl (no file needed): the OpenGL vendor, renderer and version of an offscreen "
                          "render window, and the backend the render setting backend=auto picks for each view kind.")
    info.add_argument("file", nargs="?")
    info.add_argument("--gl", action="store_true", help="describe the OpenGL driver and the backends auto picks")
    info.add_argument("--json", action="store_true", help="print JSON instead of text")
    _data_options(info)

    render = sub.add_parser("render", help="render a session or data file offscreen to an image or a movie",
                            description="Render offscreen to an image (.png, .jpg/.jpeg, .tif/.tiff) or, with "
                            "--orbit, --time or --path, to a movie (.mp4, .m4v, .mov, or a folder of PNG frames).")
    render.add_argument("target", help="a session (.json), a data file (a member of a numbered series shows its own "
                        "time step), 'demo' or 'demo-volume'")
    render.add_argument("-o", "--output", required=True,
                        help="the image or movie; the format follows the extension")
    render.add_argument("--size", type=image_size, default=None,
                        help="WIDTHxHEIGHT (default: the session's, or 1024x768)")
    _data_options(render)
    render.add_argument("--path", default=None, help="a movie along this recorded camera path of the session")
    render.add_argument("--orbit", action="store_true",
                        help="a movie orbiting the view: one full turn around the view-up axis over --duration")
    render.add_argument("--time", action="store_true", help="a movie through the time series")
    render.add_argument("--fps", type=MOVIE_FPS, default=24.0, help="movie frames per second (default 24)")
    render.add_argument("--duration", type=float_in(0.0, MAX_MOVIE_SECONDS, low_open=True), default=None,
                        help="movie length in seconds (default: the path's, 8 s for --orbit, the series' time span "
                        "for --time)")

    bench = sub.add_parser("bench", help="speed-against-error benchmarks",
                           description="Speed-against-error benchmarks; `volviz bench NAME --help` shows the options "
                           "of one.")
    names = bench.add_subparsers(dest="name", metavar="NAME", parser_class=UsageParser, required=True)
    for name, text in BENCHMARKS.items():
        names.add_parser(name, help=text, add_help=False)

    sub.add_parser("compress", help="compress a regular volume or a time series (see `volviz compress --help`)",
                   add_help=False)
    schema = sub.add_parser("schema", help="print the JSON schema of a session file",
                            description="The JSON schema (draft 2020-12) of a volviz session file: every component "
                            "type's settings and the render options with their types, ranges and defaults "
                            "(docs/session.schema.json holds it).")
    schema.add_argument("-o", "--output", default=None, help="write it to this file instead of printing it")
    sub.add_parser("warmup", help="compile the rendering kernels once, ahead of first use (the setup script runs it)",
                   description="Compile the rendering kernels once into Numba's disk cache, ahead of first use.")
    return parser


@contextmanager
def _reading(path: str | os.PathLike, q: Optional[str]) -> Iterator[None]:
    """Reading ``path`` (with the PLOT3D solution file ``q``) inside: a missing ``q`` and an option the reader does not
    take are usage errors, and a solution file given alone says what to do instead of failing to read."""
    # NumPy and the readers: loaded by the commands that read, not by --help or a refused argument
    from volviz.io import ReadError
    from volviz.io.loaders import ReaderOptionError

    if q is not None and not Path(q).is_file():
        raise UsageError(f"--q {q}: no such file")
    try:
        yield
    except ReaderOptionError as exc:
        raise UsageError(f"--option: {exc}") from None
    except ReadError:
        hint = None if q else plot3d_solution_hint(path)
        if hint:
            raise UsageError(hint) from None
        raise


def plot3d_solution_hint(path: str | os.PathLike) -> Optional[str]:
    """What to do with a PLOT3D solution (q) file opened alone, or None when ``path`` is not one."""
    # NumPy and the readers: loaded by the commands that read, not by --help or a refused argument
    from volviz.io.plot3d_pairs import grid_of_solution, is_plot3d_solution

    p = Path(path)
    if not is_plot3d_solution(p):
        return None
    grid = grid_of_solution(p)
    example = f"volviz render {grid or 'GRID_FILE'} --q {p} -o image.png"
    return (f"{p} is a PLOT3D solution (q) file: open its grid file and give this one with --q, e.g. {example}")


def describe(path: str, array: Optional[str] = None, q: Optional[str] = None,
             reader_options: Optional[dict[str, Any]] = None) -> dict[str, Any]:
    """Kind, dimensions, counts, arrays (association, components, range, non-finite values), time steps and series
    membership of a data file (or the header of a .vvz compressed volume / .vvs compressed series)."""
    p = Path(path)
    if p.suffix.lower() in (".vvz", ".vvs"):
        if array is not None or q is not None or reader_options:
            raise UsageError("--array, --q and --option apply to data files, not to compressed volumes")
        if p.suffix.lower() == ".vvz":
            # the wavelet codec (NumPy, its Numba kernels): only for a .vvz file
            from volviz.regular.codec import info as vvz_info

            return {"file": str(p), **vvz_info(p)}
        # the animated codec: only for a compressed series
        from volviz.regular.animation import series_info

        return {"file": str(p), **series_info(p)}
    # NumPy and the readers: loaded by the commands that read, not by --help or a refused argument
    from volviz.model import TimeSeries
    from volviz.model.arrays import default_array, list_arrays, select_array

    from volviz.io import read

    with _reading(p, q):
        options: dict[str, Any] = {**(reader_options or {}), **({"q": q} if q else {})}
        dataset = read(p, **options)
    base = dataset.frame(0) if isinstance(dataset, TimeSeries) else dataset
    desc: dict[str, Any] = {"file": str(p), "kind": dataset.kind, "dimensions": list(dataset.dimensions),
                            "points": dataset.n_points, "cells": dataset.n_cells}
    shown = array or default_array(base)
    if shown is not None:
        try:
            desc["range"] = _finite(select_array(base, shown).scalar_range())
        except ValueError as exc:
            raise UsageError(f"--array {array}: {exc}") from None
        desc["array"] = shown
    else:  # an image or height map: its values, no named arrays
        desc["range"] = _finite(base.scalar_range())
    arrays = list_arrays(base)
    if arrays:
        desc["arrays"] = [{"name": a.name, "association": a.association, "components": a.components,
                           "range": _finite(a.range), "nonfinite": a.nonfinite, "choices": a.choices}
                          for a in arrays]
    if isinstance(dataset, TimeSeries):
        desc["time_steps"] = dataset.n_steps
        desc["times"] = [float(dataset.times[0]), float(dataset.times[-1])]
    series = _series_membership(p)
    if series is not None:
        desc["series"] = series
    for attr in ("spacing", "origin"):
        if hasattr(dataset, attr):
            desc[attr] = list(getattr(dataset, attr))
    return desc


def describe_gl() -> dict[str, Any]:
    """The OpenGL driver of an offscreen VTK render window, the backend "auto" picks on it for each view kind, and
    whether "auto" draws the GPU backend's PT volumes in a thread of their own there (``volviz.render.backend``)."""
    # heavy: VTK's rendering, only for --gl
    from volviz.render.backend import VIEW_KINDS, choose_backend, gpu_in_thread, offscreen_gl_info

    info = offscreen_gl_info()
    return {"opengl_vendor": info.vendor, "opengl_renderer": info.renderer, "opengl_version": info.version,
            "software_rasteriser": info.software,
            "auto_backend": {kind: choose_backend("auto", kind, info) for kind in VIEW_KINDS},
            "auto_gpu_pt_in_thread": gpu_in_thread({}, info)}


def _finite(pair: Sequence[float]) -> list[Optional[float]]:
    """A (min, max) pair for JSON: NaN (no finite value) becomes null."""
    return [float(v) if math.isfinite(v) else None for v in pair]


def _series_membership(path: Path) -> Optional[dict[str, Any]]:
    """Which numbered series ``path`` belongs to (the pattern, its position, its time), or None."""
    # NumPy and the readers: loaded by the commands that read, not by --help or a refused argument
    from volviz.io.series import expand_pattern, member_time
    from volviz.scene.series import series_pattern

    pattern = series_pattern(path)
    if pattern is None:
        return None
    members = [m.resolve() for _, m in expand_pattern(pattern)]
    return {"pattern": pattern, "member": members.index(path.resolve()) + 1, "members": len(members),
            "time": member_time(pattern, path)}


def _print_info(desc: dict[str, Any]) -> None:
    width = max(len(k) for k in desc)
    for key, value in desc.items():
        if key == "arrays":
            _print_arrays(value, width)
            continue
        if key == "auto_backend":
            value = ", ".join(f"{kind}: {backend}" for kind, backend in value.items())
        elif key == "series":
            value = (f"member {value['member']} of {value['members']} of the series {value['pattern']} (time "
                     f"{value['time']:g}); `volviz render` shows this member's time step")
        elif isinstance(value, list):
            value = " x ".join(str(v) for v in value) if key == "dimensions" else ", ".join(
                f"{v:g}" if isinstance(v, float) else "none" if v is None else str(v) for v in value)
        print(f"{key:<{width}}  {value}")


def _print_arrays(arrays: list[dict[str, Any]], width: int) -> None:
    """One line per array: name, association, components, finite range, non-finite values, the specs to choose."""
    names = max((len(a["name"]) for a in arrays), default=0)
    for i, a in enumerate(arrays):
        lo, hi = a["range"]
        rng = "no finite values" if lo is None else f"{lo:g} .. {hi:g}"
        choices = f"  (--array {' | '.join(a['choices'])})" if a["choices"] != [a["name"]] else ""
        print(f"{'arrays' if i == 0 else '':<{width}}  {a['name']:<{names}}  {a['association']:<5}  "
              f"{a['components']} component{'s' if a['components'] > 1 else ' '}  range {rng}  "
              f"non-finite {a['nonfinite']}{choices}")


def run(argv: Optional[Sequence[str]] = None) -> int:
    args, rest = build_parser().parse_known_args(argv)
    if rest and args.command not in PASSED_ON:
        raise UsageError(f"unrecognized arguments: {' '.join(rest)}")
    if args.command is None:
        raise UsageError("a command is needed: info, render, bench, compress, schema or warmup (see volviz --help)")
    if args.command == "info":
        if args.file is None and not args.gl:
            raise UsageError("info needs a file, or --gl (see volviz info --help)")
        desc = describe(args.file, args.array, args.q, dict(args.option)) if args.file is not None else {}
        if args.gl:
            desc.update(describe_gl())
        if args.json:
            print(json.dumps(desc, indent=2))
        else:
            _print_info(desc)
        return 0
    if args.command == "render":
        return _render(args)
    if args.command == "bench":
        # the benchmarks and their dependencies: only for volviz bench
        from volviz.bench import require_plotting

        require_plotting(args.name)
        module = importlib.import_module(f"volviz.bench.{args.name}")
        return int(module.main(list(rest)) or 0)
    if args.command == "compress":
        # the wavelet codec (Numba kernels): only for volviz compress
        from volviz.regular.cli import compress_main

        return int(compress_main(list(rest)) or 0)
    if args.command == "warmup":
        return _warmup()
    if args.command == "schema":
        # pydantic's session models: only for volviz schema
        from volviz.model.session_schema import session_schema_text

        if args.output:
            # NumPy and the readers: loaded by the commands that read, not by --help or a refused argument
            from volviz.io.atomic import atomic_write_bytes

            atomic_write_bytes(args.output, session_schema_text().encode("utf-8"))
        else:
            sys.stdout.write(session_schema_text())
        return 0
    raise UsageError(f"unknown command {args.command}")


def _render(args: argparse.Namespace) -> int:
    movie = args.path is not None or args.time or args.orbit
    if args.path is not None and args.orbit:
        raise UsageError("--orbit and --path each move the camera: give one")
    if not movie and args.duration is not None:
        raise UsageError("--duration applies to movies (--orbit, --time or --path)")
    if args.duration is not None and args.fps * args.duration > MAX_MOVIE_FRAMES:
        raise UsageError(f"--duration {args.duration:g} at --fps {args.fps:g} makes "
                         f"{args.fps * args.duration:.0f} frames; at most {MAX_MOVIE_FRAMES}")
    target = Path(args.target)
    if str(args.target) not in ("demo", "demo-volume") and target.exists():   # a session's format starts no child
        _start_reader(target, {**dict(args.option), **({"q": args.q} if args.q else {})})
    # the render layer (pyvista, VTK's rendering): heavy, imported while the reader child starts
    from volviz.render.export import (check_image_size, check_output, is_session_file, open_target, render_movie,
                                      render_to_file)

    data_file = str(args.target) not in ("demo", "demo-volume") and not is_session_file(target)
    if not data_file and (args.array is not None or args.q is not None or args.option):
        raise UsageError("--array, --q and --option apply to data files (a session names the array of each "
                         "component and the options of each dataset)")
    if data_file and not target.exists():
        raise UsageError(f"{target}: no such file (give a session, a data file, 'demo' or 'demo-volume')")
    check_output(args.output, movie)
    session, session_file = open_target(args.target, args.array, args.q, dict(args.option))
    size = args.size or session.render.size
    check_image_size(size)
    datasets: dict[str, Any] = {}
    if data_file:
        _read_for_render(session, datasets, args)
    if not movie:
        out = render_to_file(session, session_file, args.output, size, datasets=datasets)
        print(f"wrote {out} ({size[0]}x{size[1]})")
        return 0

    def progress(fraction: float, message: str) -> None:
        print(f"\r{message} ({fraction:4.0%})", end="", file=sys.stderr, flush=True)

    out = render_movie(session, session_file, args.output, size, path_name=args.path, fps=args.fps,
                       through_time=args.time, duration=args.duration, progress=progress, orbit=args.orbit,
                       datasets=datasets)
    print(file=sys.stderr)
    print(f"wrote {out} ({size[0]}x{size[1]})")
    return 0


def _start_reader(path: Path, options: dict[str, Any]) -> None:
    """Start the reader child now when ``path``'s reader runs in one (``volviz.io.isolated``): the child is a fresh
    interpreter (a crash cannot take the render with it), so its start (Python, numpy, ``volviz.io``) overlaps the
    import of the render layer instead of following it (issue #31, docs/architecture.md "Start-up"); ``_render``
    calls it before that import. A session file's format is none a reader takes: it starts no child."""
    # NumPy and the readers: loaded by the commands that read, not by --help or a refused argument
    from volviz.io import ReadError, isolated
    from volviz.io.registry import format_of, get_reader

    try:
        isolates = get_reader(format_of(path, options)).isolated
    except (ReadError, OSError, KeyError, ValueError):   # the read itself says what is wrong with the file
        return
    if isolates and isolated.isolation_enabled():
        isolated.prewarm(idle_load=False)   # its one read comes soon: no reader's VTK modules it may not use


def _read_for_render(session: Any, datasets: dict[str, Any], args: argparse.Namespace) -> None:
    """Read a data file's dataset into ``datasets`` (a PLOT3D solution file given alone says what to do) and check
    that it has the ``--array`` asked for (a usage error naming the arrays it has)."""
    # the scene layer (NumPy, readers, Numba): only for volviz render
    from volviz.scene.datasets import read_any, shown_array

    ref = session.datasets[0]
    with _reading(args.target, args.q):
        datasets[ref.id] = read_any(Path(ref.path), ref.options)
    if args.array is not None:
        try:
            shown_array(datasets[ref.id], args.array)
        except ValueError as exc:
            raise UsageError(f"--array {args.array}: {exc}") from None


def _warmup() -> int:
    # heavy: every kernel and VTK's rendering, only for volviz warmup
    from volviz.warmup import warm_up

    def progress(fraction: float, message: str) -> None:
        print(f"\r{message} ({fraction:4.0%})\033[K", end="", file=sys.stderr, flush=True)

    timings = warm_up(progress)
    print(file=sys.stderr)
    print("kernels ready: " + ", ".join(f"{name} {seconds:.1f} s" for name, seconds in timings))
    return 0


#: (defining module, class) of the user errors of volviz's layers
LAYER_ERRORS = (("volviz.io.errors", "ReadError"), ("volviz.session", "SessionError"),
                ("volviz.scene.errors", "SceneError"), ("volviz.render.export", "ExportError"),
                ("volviz.io.atomic", "OutputPathError"))


def user_errors() -> tuple[type[BaseException], ...]:
    """The exceptions that are the user's errors (one line, exit 2). A layer's error class is taken only from a module
    the command loaded, since only a loaded module can have raised it: a refused file is not followed by an import of
    the render layer (VTK's rendering, most of a failed ``volviz info``'s time; docs/bench/docstring-figures.md)."""
    loaded = tuple(getattr(sys.modules[module], name) for module, name in LAYER_ERRORS if module in sys.modules)
    return (UsageError, *loaded, FileNotFoundError, IsADirectoryError, PermissionError)


def _one_line(text: object) -> str:
    return " ".join(str(text).splitlines())


def _show_warning(message: Warning | str, category: type[Warning], filename: str, lineno: int, file: Any = None,
                  line: Optional[str] = None) -> None:
    """Warnings (e.g. a file's non-finite values) as one line ``volviz: warning: ...``, without source lines."""
    print(f"volviz: warning: {_one_line(message)}", file=sys.stderr)


#: the garbage collector's thresholds of the ``volviz`` program (``gc.set_threshold``; Python's are 700, 10, 10)
PROGRAM_GC_THRESHOLDS = (10_000, 10, 10)


def _as_program() -> None:
    """Garbage collection for a run of the ``volviz`` program: a first generation of 10,000 objects instead of 700,
    so that the start-up's imports (hundreds of thousands of objects that live to the end) are not traversed again
    and again (issue #30: a Blunt Fin render ran 555 young, 50 middle and 4 full collections, 0.30 s of CPU; with
    these thresholds 39, 3 and 0, 0.12 s, the same peak memory), and no collection at the exit
    (``_no_collection_at_exit``)."""
    gc.set_threshold(*PROGRAM_GC_THRESHOLDS)
    atexit.register(_no_collection_at_exit)


def _no_collection_at_exit() -> None:
    """The interpreter's exit skips the garbage collector's last passes over every object still alive: they only
    free memory the exit returns anyway, and cost up to a second after a render had written its image (issue #30,
    time to the first image; docs/bench/docstring-figures.md): ``gc.freeze`` moves them out of the collector's
    reach. Run last among the exit handlers, so that those (the reader child's shutdown, ``weakref.finalize``)
    still run."""
    gc.freeze()


def main(argv: Optional[Sequence[str]] = None) -> int:
    """``volviz`` with ``argv`` (default: the command line); the exit code. Called without ``argv`` (the program
    itself: the console script, ``python -m volviz.cli``), the process collects its garbage as a program
    (``_as_program``); a caller in-process keeps its own collector's settings."""
    if argv is None:
        _as_program()
    debug = "--debug" in (sys.argv[1:] if argv is None else argv)
    try:
        with warnings.catch_warnings():
            if not debug:
                warnings.showwarning = _show_warning
            return run(argv)
    except SystemExit as exc:  # --version / --help (an int code), or a sub-command's usage message (a str code)
        if isinstance(exc.code, str):
            print(f"volviz: error: {_one_line(exc.code)}", file=sys.stderr)
            return 2
        return int(exc.code or 0)
    except KeyboardInterrupt:
        print("volviz: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader of the output went away (``volviz info X | head``): not an error of ours
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())   # no second error when Python flushes
        return 0
    except Exception as exc:
        if isinstance(exc, user_errors()):
            print(f"volviz: error: {_one_line(exc)}", file=sys.stderr)
            return 2
        if debug:
            raise
        print(f"volviz: internal error: {type(exc).__name__}: {_one_line(exc)} (run with --debug for details)",
              file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
