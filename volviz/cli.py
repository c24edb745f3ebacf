"""The `volviz` command line: info, render, bench, compress. Never imports Qt.

User errors (unreadable files, bad sessions, bad arguments) print one line ``volviz: error: ...`` and exit 2; an
unexpected failure prints one line too (``--debug`` shows the traceback) and exits 1.
"""
from __future__ import annotations

import argparse
import importlib
import json
import os
import sys
from pathlib import Path
from typing import Any, Optional, Sequence

import volviz

BENCHMARKS = ("tables", "unstructured", "compression", "nature", "iso")


class UsageError(Exception):
    """A bad command-line value."""


def _size(text: str) -> tuple[int, int]:
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, e.g. 800x600, got {text!r}") from None
    if not (1 <= w <= 16384 and 1 <= h <= 16384):
        raise argparse.ArgumentTypeError(f"image size must be 1..16384 on each side, got {text!r}")
    return (w, h)


class _Parser(argparse.ArgumentParser):
    def error(self, message: str) -> None:  # one line, no usage dump
        raise UsageError(message)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="volviz", description="Accurate, fast volume rendering.")
    parser.add_argument("--version", action="version", version=f"volviz {volviz.__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks of unexpected errors")
    sub = parser.add_subparsers(dest="command", parser_class=_Parser)

    info = sub.add_parser("info", help="describe a data file or a compressed volume")
    info.add_argument("file")
    info.add_argument("--json", action="store_true", help="print JSON instead of text")

    render = sub.add_parser("render", help="render a session or data file offscreen to PNG")
    render.add_argument("target", help="a session (.json), a data file, or 'demo'")
    render.add_argument("-o", "--output", required=True, help="output PNG")
    render.add_argument("--size", type=_size, default=None, help="WIDTHxHEIGHT (default: the session's, or 1024x768)")
    render.add_argument("--path", default=None, help="render a movie along this recorded camera path")
    render.add_argument("--time", action="store_true", help="render a movie through the time series")
    render.add_argument("--fps", type=float, default=24.0, help="movie frames per second (default 24)")
    render.add_argument("--duration", type=float, default=None, help="movie length in seconds (default: the path's)")

    bench = sub.add_parser("bench", help="speed-against-error benchmarks", add_help=False)
    bench.add_argument("name", choices=BENCHMARKS)
    bench.add_argument("args", nargs=argparse.REMAINDER)

    compress = sub.add_parser("compress", help="compress a regular volume (see `volviz compress --help`)",
                              add_help=False)
    compress.add_argument("args", nargs=argparse.REMAINDER)

    sub.add_parser("warmup", help="compile the rendering kernels once, ahead of first use (the setup script runs it)")
    return parser


def describe(path: str) -> dict[str, Any]:
    """Kind, dimensions, counts, ranges and time steps of a data file (or a .vvz compressed volume)."""
    p = Path(path)
    if p.suffix.lower() == ".vvz":
        from volviz.regular.codec import info as vvz_info

        return {"file": str(p), **vvz_info(p)}
    if p.suffix.lower() == ".vvs":
        from volviz.regular.animation import series_info

        return {"file": str(p), **series_info(p)}
    from volviz.io import read
    from volviz.model import TimeSeries

    dataset = read(p)
    desc: dict[str, Any] = {"file": str(p), "kind": dataset.kind, "dimensions": list(dataset.dimensions),
                            "points": dataset.n_points, "cells": dataset.n_cells}
    lo, hi = dataset.scalar_range()
    desc["range"] = [lo, hi]
    if isinstance(dataset, TimeSeries):
        desc["time_steps"] = dataset.n_steps
        desc["times"] = [float(dataset.times[0]), float(dataset.times[-1])]
    for attr in ("spacing", "origin"):
        if hasattr(dataset, attr):
            desc[attr] = list(getattr(dataset, attr))
    arrays = getattr(dataset, "point_data", None)
    if arrays:
        desc["arrays"] = sorted(arrays)
    return desc


def _print_info(desc: dict[str, Any]) -> None:
    width = max(len(k) for k in desc)
    for key, value in desc.items():
        if isinstance(value, list):
            value = " x ".join(str(v) for v in value) if key == "dimensions" else ", ".join(f"{v:g}" if isinstance(
                v, float) else str(v) for v in value)
        print(f"{key:<{width}}  {value}")


def run(argv: Optional[Sequence[str]] = None) -> int:
    args = build_parser().parse_args(argv)
    if args.command is None:
        raise UsageError("a command is needed: info, render, bench, compress or warmup (see volviz --help)")
    if args.command == "info":
        desc = describe(args.file)
        if args.json:
            print(json.dumps(desc, indent=2))
        else:
            _print_info(desc)
        return 0
    if args.command == "render":
        return _render(args)
    if args.command == "bench":
        module = importlib.import_module(f"volviz.bench.{args.name}")
        return int(module.main(list(args.args)) or 0)
    if args.command == "compress":
        from volviz.regular.cli import compress_main

        return int(compress_main(list(args.args)) or 0)
    if args.command == "warmup":
        return _warmup()
    raise UsageError(f"unknown command {args.command}")


def _render(args: argparse.Namespace) -> int:
    from volviz.render.export import is_session_file, render_movie, render_to_png
    from volviz.session import load

    target = Path(args.target)
    session = load(target) if is_session_file(target) else None
    size = args.size or (session.render.size if session is not None else (1024, 768))
    movie = args.path is not None or args.time or Path(args.output).suffix.lower() in (".mp4", ".m4v", ".mov")
    if not movie:
        out = render_to_png(args.target, args.output, size)
        print(f"wrote {out} ({size[0]}x{size[1]})")
        return 0
    if session is None:
        raise UsageError("movies are rendered from a session file (camera paths and time live there)")
    if args.fps <= 0:
        raise UsageError(f"--fps must be positive, got {args.fps}")

    def progress(fraction: float, message: str) -> None:
        print(f"\r{message} ({fraction:4.0%})", end="", file=sys.stderr, flush=True)

    out = render_movie(session, target, args.output, size, path_name=args.path, fps=args.fps,
                       through_time=args.time, duration=args.duration, progress=progress)
    print(file=sys.stderr)
    print(f"wrote {out} ({size[0]}x{size[1]})")
    return 0


def _warmup() -> int:
    from volviz.warmup import warm_up

    def progress(fraction: float, message: str) -> None:
        print(f"\r{message} ({fraction:4.0%})\033[K", end="", file=sys.stderr, flush=True)

    timings = warm_up(progress)
    print(file=sys.stderr)
    print("kernels ready: " + ", ".join(f"{name} {seconds:.1f} s" for name, seconds in timings))
    return 0


def user_errors() -> tuple[type[BaseException], ...]:
    from volviz.io import ReadError
    from volviz.render.scene import SceneError
    from volviz.session import SessionError

    return (UsageError, ReadError, SessionError, SceneError, FileNotFoundError, IsADirectoryError, PermissionError)


def main(argv: Optional[Sequence[str]] = None) -> int:
    debug = "--debug" in (sys.argv[1:] if argv is None else argv)
    try:
        return run(argv)
    except SystemExit as exc:  # --version / --help (an int code), or a sub-command's usage message (a str code)
        if isinstance(exc.code, str):
            print(f"volviz: error: {exc.code}", file=sys.stderr)
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
            print(f"volviz: error: {exc}", file=sys.stderr)
            return 2
        if debug:
            raise
        print(f"volviz: internal error: {type(exc).__name__}: {exc} (run with --debug for details)", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
