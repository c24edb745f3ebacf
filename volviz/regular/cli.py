"""``volviz compress``: the command-line front end of the wavelet codec (Guthe §2.2, §2.3).

``volviz compress IN -o OUT --series [--pattern IBBPBBPPB] [--quality Q | --lossless] [--scheduler ADDRESS]`` reads
IN as a time series (e.g. ``Storm.pvm-t%02d``) and writes a motion-compensated I/P/B store directory
(:mod:`.animation`); with ``--scheduler`` the parts between I volumes are encoded on a dask.distributed cluster
(the ``dask`` compression backend of the volviz-dask plugin, :mod:`.backends`),
bit-identical to a local run.

``volviz compress IN -o OUT [--quality Q | --psnr DB | --lossless] [--coder rans|arith]`` reads IN with
``volviz.io.read`` (any supported volume), or -- for volumes larger than memory -- a headerless raw file given with
``--raw NX NY NZ --dtype uint8``, which is memory-mapped and compressed out of core. A text progress bar goes to
stderr.
``volviz info OUT.vvz`` (in :mod:`volviz.cli`) describes the result.
"""
from __future__ import annotations

import argparse
import json
import re
import socket
import sys
import time
from typing import Any, Sequence

import numpy as np

from volviz.argtypes import UsageParser, float_in, int_in
from volviz.model.datasets import RegularVolume

from .codec import compress


def _progress_bar(stream: Any = None) -> Any:
    """A text progress bar on ``stream`` (default: the ``sys.stderr`` of the moment it is made, not of import time)."""
    stream = sys.stderr if stream is None else stream
    start = time.perf_counter()

    def report(fraction: float, message: str) -> None:
        width = 30
        filled = int(round(width * min(max(fraction, 0.0), 1.0)))
        stream.write(f"\r[{'#' * filled}{'.' * (width - filled)}] {100 * fraction:5.1f}% "
                     f"{time.perf_counter() - start:6.1f}s {message[:40]:<40}")
        if fraction >= 1.0:
            stream.write("\n")
        stream.flush()

    return report


def _raw_input(args: argparse.Namespace) -> None:
    """``--raw`` input checked before it is memory-mapped: a regular file (a FIFO or device would block the map, as
    ``volviz info`` refuses them: ``volviz.io._checks.check_file``) holding exactly NX*NY*NZ samples."""
    # the readers (registry and plugins): only for raw input
    from volviz.io._checks import file_size

    nx, ny, nz = args.raw
    dtype = np.dtype(args.dtype)
    size = file_size(args.input)  # ReadError (a user error) for a missing file, a folder, FIFO or device
    need = nx * ny * nz * dtype.itemsize
    if need != size:
        raise SystemExit(f"--raw {nx} {ny} {nz} --dtype {dtype.name} needs {need} bytes, but {args.input} holds "
                         f"{size} bytes ({'fewer' if size < need else 'more'}): give its dimensions and --dtype")


def _load(args: argparse.Namespace) -> RegularVolume:
    if args.raw:
        _raw_input(args)
        nx, ny, nz = args.raw
        dtype = np.dtype(args.dtype)
        data = np.memmap(args.input, dtype=dtype, mode="r", shape=(nx, ny, nz), order="F")
        return RegularVolume(data=data, source=args.input)
    # the readers (registry and plugins): only for a subcommand that reads a file
    from volviz.io import read

    vol = read(args.input)
    if not isinstance(vol, RegularVolume):
        raise SystemExit(f"{args.input}: a {getattr(vol, 'kind', type(vol).__name__)} is not a regular volume")
    return vol


def _gop_pattern(text: str) -> str:
    """An argument type: a GOP pattern ``frame_types`` accepts (I first, then I, P and B)."""
    # the animation codec (Numba kernels): only for a series
    from .animation import frame_types

    try:
        frame_types(1, text)
    except ValueError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None
    return text


def compress_main(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``volviz compress``; returns the process exit code."""
    p = UsageParser(prog="volviz compress", description="Compress a regular volume to .vvz "
                    "(integer 5/3 wavelet octree + rANS / arithmetic coding)")
    p.add_argument("input")
    p.add_argument("-o", "--output", required=True, help="output .vvz file")
    mode = p.add_mutually_exclusive_group()
    mode.add_argument("--lossless", action="store_true", help="bit-exact (default)")
    mode.add_argument("--quality", type=float_in(0.0, 100.0), help="0..100; 90 ~ 1 voxel-unit quantiser step")
    mode.add_argument("--psnr", type=float_in(0.0, 200.0, low_open=True),
                      help="search the quantiser step to reach this PSNR (dB)")
    p.add_argument("--coder", choices=("rans", "arith"), default="rans",
                   help="rans: fast decoding (default); arith: adaptive arithmetic coding, higher ratio")
    p.add_argument("--transform", choices=("auto", "5/3", "haar"), default="auto",
                   help="lossless files: code each octree node with the 5/3 and the integer S-transform and keep the "
                   "smaller (auto, default), or force one; lossy files always use the 5/3")
    p.add_argument("--raw", type=int_in(1), nargs=3, metavar=("NX", "NY", "NZ"),
                   help="INPUT is a headerless raw volume (x fastest), memory-mapped and compressed out of core")
    p.add_argument("--dtype", default="uint8", choices=("uint8", "uint16", "int16", "float32"),
                   help="sample type of --raw input")
    p.add_argument("--series", action="store_true",
                   help="INPUT is a time series of 8-bit volumes (e.g. Storm.pvm-t%%02d); "
                   "OUTPUT a .vvs store directory")
    p.add_argument("--pattern", type=_gop_pattern, default="IBBPBBPPB",
                   help="GOP pattern of --series (I, IPP, IBB, IBBPBBPPB, ...)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="--series only: encode on this dask.distributed scheduler (e.g. tcp://host:8786), one task "
                   "per I-to-I part; the output is bit-identical to a local run (needs the volviz-dask plugin)")
    p.add_argument("--quiet", action="store_true")
    p.add_argument("--json", help="write the resulting info as JSON to this file")
    args = p.parse_args(list(argv) if argv is not None else None)
    if args.series:
        return _series_main(args)
    if args.transform != "auto" and (args.quality is not None or args.psnr is not None):
        raise SystemExit("--transform applies to lossless files (lossy files always use the 5/3 wavelet)")
    if args.scheduler:
        raise SystemExit("--scheduler applies to --series (a single volume is compressed out of core locally)")
    vol = _load(args)
    result = compress(vol, args.output, quality=args.quality, psnr=args.psnr, coder=args.coder,
                      progress=None if args.quiet else _progress_bar(), transform=args.transform)
    _print_info(result)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)
    return 0


def _series_main(args: argparse.Namespace) -> int:
    # the readers and the animation codec (Numba kernels): only for a series
    from volviz.io import read
    from volviz.model.datasets import TimeSeries

    from .animation import compress_series

    if args.psnr is not None or args.raw:
        raise SystemExit("--series supports --lossless or --quality (not --psnr or --raw)")
    if args.scheduler:
        # a compression backend is a plugin: only when one is named
        from .backends import BackendMissing, compression_backend

        try:
            compression_backend("dask")
        except BackendMissing as exc:
            raise SystemExit(f"--scheduler: {exc}") from None
        _check_scheduler(args.scheduler)
    series = read(args.input)
    if not isinstance(series, TimeSeries):
        raise SystemExit(f"{args.input}: not a time series (use a numbered pattern such as Storm.pvm-t%02d)")
    result = compress_series(series, args.output, pattern=args.pattern,
                             mode="lossless" if args.quality is None else "quality", quality=args.quality,
                             progress=None if args.quiet else _progress_bar(), scheduler=args.scheduler)
    print(f"{result['n']} volumes {tuple(result['dims'])}  pattern {result['pattern']}  {result['mode']}  "
          f"{result['bytes']} bytes  ratio {result['ratio']:.2f}:1  {result['bits_per_voxel']:.3f} bits/voxel")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=1)
    return 0


SCHEDULER_TIMEOUT = 5.0  # seconds a scheduler has to accept a connection (dask's own client waits 30 s)
_ADDRESS = re.compile(r"(?:tcp://)?(?P<host>\[[^\]]+\]|[^:/\[\]]+):(?P<port>\d{1,5})/?\Z")


def _check_scheduler(address: str, timeout: float = SCHEDULER_TIMEOUT) -> None:
    """Fail fast, as a usage error and before anything is read or written, unless a dask scheduler answers at
    ``address`` (``tcp://HOST:PORT`` or ``HOST:PORT``; other transports are left to the backend). A scheduler sends
    its handshake as soon as a client connects, a message that starts with its length (u64, distributed's TCP
    framing); a host that accepts the connection but says nothing, or something else, is no scheduler."""
    scheme = address.split("://", 1)[0] if "://" in address else "tcp"
    if scheme != "tcp":  # inproc://, tls://, ucx://: the backend connects itself
        return
    m = _ADDRESS.match(address)
    if m is None:
        raise SystemExit(f"--scheduler {address!r}: not an address of the form tcp://HOST:PORT")
    host, port = m["host"].strip("[]"), int(m["port"])
    head = b""
    try:
        with socket.create_connection((host, port), timeout=timeout) as conn:
            deadline = time.monotonic() + timeout
            while len(head) < 8 and time.monotonic() < deadline:
                conn.settimeout(max(deadline - time.monotonic(), 0.01))
                chunk = conn.recv(8 - len(head))
                if not chunk:
                    break
                head += chunk
    except TimeoutError:
        pass
    except OSError as exc:
        raise SystemExit(f"--scheduler {address}: no scheduler reachable at {host}:{port} "
                         f"({exc.strerror or type(exc).__name__})") from None
    if len(head) < 8:
        raise SystemExit(f"--scheduler {address}: {host}:{port} accepted the connection but sent no scheduler "
                         f"handshake within {timeout:g} s (got {len(head)} bytes)")
    size = int.from_bytes(head, "little")
    if not 0 < size < 1 << 26:
        raise SystemExit(f"--scheduler {address}: {host}:{port} answers, but not as a dask scheduler (its first "
                         f"message claims {size} bytes)")


def _print_info(meta: dict[str, Any]) -> None:
    psnr = "lossless" if meta.get("lossless") else (f"{meta['psnr']:.2f} dB" if meta.get("psnr") else "n/a")
    print(f"dims {tuple(meta['dims'])} {meta['dtype']}  levels {meta['levels']}  bricks {meta['bricks']} "
          f"({meta['stripped_bricks']} stripped, {meta.get('haar_bricks', 0)} S-transform)  coder {meta['coder']}")
    print(f"{meta['original_bytes']} -> {meta['file_bytes']} bytes  ratio {meta['ratio']:.2f}:1  "
          f"{meta['bits_per_voxel']:.3f} bits/voxel  PSNR {psnr}")


if __name__ == "__main__":  # pragma: no cover
    sys.exit(compress_main())
