"""Benchmark: what crash-isolated reading costs (``volviz bench isolation``).

Every file in the shared data folder that an isolated reader opens (VTK legacy and XML, VTKHDF, and the VTK-readers
plugin's Exodus, OpenFOAM, CGNS, netCDF ...), plus two large files written here into a temporary folder (a VTK XML
image and a VTK XML hexahedral mesh of about ``--large-mb`` MB each), is read with ``volviz.io.read`` in-process
(``isolate=False``) and isolated (a warm reader child), each the median of ``--repeats`` reads after a warm-up. A time
series is also read with all its frames (each lazy frame is one more isolated read). The first read in a fresh
process (starting the child: Python, NumPy, VTK) is timed separately. Writes ``docs/bench/isolation.md`` with the
command line, and optionally ``--json OUT``.

Target (volviz issue 15): isolated reading must not double the load time of large files.
"""
from __future__ import annotations

import json
import os
import platform
import shlex
import statistics
import sys
import tempfile
import time
from pathlib import Path
from typing import Any, Callable

import numpy as np

from volviz.argtypes import UsageParser, int_in

DEFAULT_DATA = Path(os.environ.get("VOLVIZ_DATA", Path(__file__).resolve().parents[2].parent / "shared" / "data"))
REPORT_DIR = Path(__file__).resolve().parents[2] / "docs" / "bench"
LARGE_RATIO_TARGET = 2.0


def isolated_inputs(root: Path) -> list[Path]:
    """Every file (or folder a reader opens whole) under ``root`` that the registry gives to an isolated reader."""
    # the readers (registry and plugins): loaded when a case first reads a file
    from volviz.io import ReadError
    from volviz.io.registry import spec_of

    found: list[Path] = []
    for folder, dirs, files in os.walk(root):
        dirs.sort()
        here = Path(folder)
        if here != root:
            try:
                spec = spec_of(here)  # a folder a reader opens whole (else ReadError)
            except ReadError:
                spec = None
            if spec is not None:
                found += [here] if spec.isolated else []
                dirs.clear()
                continue
        for name in sorted(files):
            try:
                if spec_of(here / name).isolated:
                    found.append(here / name)
            except ReadError:
                continue
    return found


def write_large(folder: Path, megabytes: int) -> list[Path]:
    """A VTK XML image (float32) and a VTK XML hexahedral mesh of about ``megabytes`` MB each, raw appended data."""
    # heavy: VTK's rendering, loaded where a case draws (not for --help or a refused argument)
    import pyvista as pv

    n = max(8, round((megabytes * 1e6 / 4) ** (1 / 3)))
    image = pv.ImageData(dimensions=(n, n, n))
    image.point_data["density"] = np.random.default_rng(1).random(n ** 3, dtype=np.float32)
    m = max(4, round((megabytes * 1e6 / (24 + 8 * 8 + 1 + 8 + 8)) ** (1 / 3)))  # points, connectivity, types, values
    mesh = pv.ImageData(dimensions=(m, m, m)).cast_to_unstructured_grid()
    mesh.point_data["temperature"] = np.linspace(0.0, 1.0, mesh.n_points)
    out = []
    for data, name in ((image, f"large-image-{n}^3.vti"), (mesh, f"large-hexmesh-{m}^3.vtu")):
        path = folder / name
        data.save(path, binary=True)
        out.append(path)
    return out


def _paired_medians(first: Callable[[], Any], second: Callable[[], Any], repeats: int) -> tuple[float, float]:
    """Median times of ``first`` and ``second`` after a warm-up of each, taken in alternating order (so that the
    drift of a shared machine's load falls on both)."""
    first(), second()  # warm-up: imports, caches, a warm reader child
    times: tuple[list[float], list[float]] = ([], [])
    for i in range(repeats):
        for k in ((0, 1) if i % 2 == 0 else (1, 0)):
            t0 = time.perf_counter()
            (first, second)[k]()
            times[k].append(time.perf_counter() - t0)
    return statistics.median(times[0]), statistics.median(times[1])


def _read_all(path: Path, isolate: bool) -> Any:
    """Read ``path``; for a time series also every later frame (each one more read)."""
    # the readers (registry and plugins): loaded when a case first reads a file
    import volviz.io as vio

    data = vio.read(path, isolate=isolate)
    if getattr(data, "kind", "") == "time series":
        for i in range(len(data)):
            data.frame(i)
    return data


def _row(path: Path, label: str, repeats: int, all_frames: bool = False) -> dict:
    # the readers (registry and plugins): loaded when a case first reads a file
    import volviz.io as vio

    read = (lambda iso: _read_all(path, iso)) if all_frames else (lambda iso: vio.read(path, isolate=iso))
    size = sum(f.stat().st_size for f in path.rglob("*") if f.is_file()) if path.is_dir() else path.stat().st_size
    inproc, iso = _paired_medians(lambda: read(False), lambda: read(True), repeats)
    return {"file": label, "bytes": size, "in_process_s": inproc, "isolated_s": iso, "overhead_s": iso - inproc,
            "ratio": iso / inproc if inproc > 0 else float("inf")}


def cold_start(path: Path, repeats: int) -> float:
    """Median time of the first isolated read after the reader children were ended (a child starts for it)."""
    # the readers (registry and plugins): loaded when a case first reads a file
    import volviz.io as vio
    from volviz.io import isolated

    times = []
    for _ in range(repeats):
        isolated.shutdown()
        t0 = time.perf_counter()
        vio.read(path)
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def run(data: Path, repeats: int, large_mb: int) -> dict:
    # the readers (registry and plugins): loaded when a case first reads a file
    import volviz.io as vio
    from volviz.io import isolated

    rows = []
    for path in isolated_inputs(data):
        label = str(path.relative_to(data))
        rows.append(_row(path, label, repeats))
        if getattr(vio.read(path), "kind", "") == "time series":
            rows.append(_row(path, label + " (every frame)", repeats, all_frames=True))
    with tempfile.TemporaryDirectory(prefix="volviz-bench-isolation-") as tmp:
        for path in write_large(Path(tmp), large_mb) if large_mb > 0 else []:
            rows.append({**_row(path, f"{path.name} (written here)", repeats), "large": True})
    probe = data / "volumes" / "hydrogen.vti"
    cold = cold_start(probe, 3) if probe.exists() else float("nan")
    return {"rows": rows, "repeats": repeats, "cold_start_s": cold, "cold_probe": str(probe.relative_to(data)),
            "exchange": isolated._exchange_base(1 << 20), "limits": vars(isolated.limits),
            "load": os.getloadavg() if hasattr(os, "getloadavg") else None}


def _targets(result: dict) -> list[str]:
    large = [r for r in result["rows"] if r.get("large")] or sorted(result["rows"], key=lambda r: r["bytes"])[-2:]
    worst = max(large, key=lambda r: r["ratio"])
    ok = worst["ratio"] < LARGE_RATIO_TARGET
    return [f"- large files: isolated / in-process load time at most {worst['ratio']:.2f} ({worst['file']}); target "
            f"< {LARGE_RATIO_TARGET:.0f} — {'met' if ok else 'NOT met'}"]


def write_report(result: dict, out_dir: Path, command: str) -> Path:
    out_dir.mkdir(parents=True, exist_ok=True)
    load = result["load"] or (float("nan"),) * 3
    overheads = [r["overhead_s"] for r in result["rows"] if not r.get("large") and "every frame" not in r["file"]]
    md = [
        "# Crash-isolated reading: what the child process costs",
        "",
        f"Command: `{command}`",
        "",
        f"Machine: {platform.machine()}, {os.cpu_count()} cores shared with other work (load average at the end "
        f"{load[0]:.1f} / {load[1]:.1f} / {load[2]:.1f}), Python {platform.python_version()}, numpy {np.__version__}.",
        f"Each time is the median of {result['repeats']} reads through `volviz.io.read` after a warm-up, in-process "
        "(`isolate=False`) and isolated (a warm reader child; arrays handed back as .npy files in "
        f"`{result['exchange']}`), the two taken in turns.",
        "",
        "## Targets",
        "",
        *_targets(result),
        f"- first read in a fresh process (starting the reader child: Python, NumPy, VTK), {result['cold_probe']}: "
        f"{result['cold_start_s']:.2f} s; later reads pay the warm overhead below (median over the shared files "
        f"{statistics.median(overheads) * 1e3:.1f} ms)" if overheads else "",
        "",
        "## Every file",
        "",
        "| file | size | in-process | isolated | overhead | ratio |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for r in result["rows"]:
        md.append(f"| {r['file']} | {r['bytes'] / 1e6:.2f} MB | {r['in_process_s'] * 1e3:.1f} ms | "
                  f"{r['isolated_s'] * 1e3:.1f} ms | {r['overhead_s'] * 1e3:+.1f} ms | {r['ratio']:.2f} |")
    md += [
        "",
        "The overhead of a warm read is the request and answer (JSON lines over pipes), writing the arrays as .npy "
        "files in the child and taking them here (arrays of 1 MB and more are mapped copy-on-write, smaller ones "
        "copied; through memory when the exchange folder is /dev/shm), and checking them against the child's "
        "description. It is a few milliseconds plus about one copy of the data; for a small file read in a few "
        "milliseconds that can double the time, for large files it is a small fraction. A time series read with "
        "every frame pays it once per frame. Reads on this shared machine vary by tens of percent from run to run, "
        "so small negative overheads are noise.",
        "",
    ]
    path = out_dir / "isolation.md"
    path.write_text("\n".join(md), encoding="utf-8")
    return path


def main(argv: list[str] | None = None) -> int:
    parser = UsageParser(prog="volviz bench isolation", description=__doc__.split("\n")[0])
    parser.add_argument("--data", metavar="DIR", type=Path, default=DEFAULT_DATA,
                        help="the shared data folder (default: $VOLVIZ_DATA or ../shared/data)")
    parser.add_argument("--out", metavar="DIR", default=None, help="report directory (default: <repo>/docs/bench)")
    parser.add_argument("--json", metavar="OUT", help="also write the raw results as JSON")
    parser.add_argument("--repeats", type=int_in(1, 1000), default=5)
    parser.add_argument("--large-mb", type=int_in(0, 4000), default=64,
                        help="size of each large file written for the run (0: none)")
    args = parser.parse_args([] if argv is None else argv)
    if not args.data.is_dir():
        parser.error(f"--data {args.data} is not a folder (set VOLVIZ_DATA)")
    result = run(args.data.resolve(), args.repeats, args.large_mb)
    command = " ".join(["volviz bench isolation", *(shlex.quote(a) for a in argv or [])])
    written = [write_report(result, Path(args.out) if args.out else REPORT_DIR, command)]
    if args.json:
        written.append(Path(args.json))
        written[-1].write_text(json.dumps(result, indent=1), encoding="utf-8")
    print("\n".join([*(f"wrote {p}" for p in written), *_targets(result)]))
    return 0

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
