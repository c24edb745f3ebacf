"""Start-up of fresh processes (issue #31): ``volviz info`` and ``volviz render`` of shared files, and the app's start
to its first frame (``volviz-app --first-frame FILE``, under a display: run this under ``xvfb-run``).

Each case runs in a fresh process: one warm-up, then ``--reps`` timed runs (median, min and max of the wall time: from
the process's spawn to its exit, for the app to the first frame it prints; the median CPU time, user + system, of the
process and the children it waited for, which a loaded machine inflates far less than the wall time), the peak
resident memory (``/usr/bin/time -v``'s maximum resident set size, the largest of the process and its waited-for
children), and one more run under ``python -X importtime``: the total import time (sum of the modules' own times) and
the largest imports started outside any other import (their cumulative times do not overlap). With ``--trees A B``
each case alternates between source trees run by run (``PYTHONPATH``; a tree needs a ``volviz_app`` link to its
``app`` folder for the app's case): a before / after comparison under the same load. The machine's load average is
reported before and after: the numbers are only comparable within one run.
"""
from __future__ import annotations

import os
import resource
import shlex
import statistics
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

from volviz.argtypes import UsageParser, int_in
from volviz.io.atomic import atomic_write_text

REPO = Path(__file__).resolve().parents[2]
#: (name, command after the interpreter, needs a display); {data} and {tmp} are filled in
CASES = [
    ("info embryo", ["-m", "volviz.cli", "info", "{data}/volumes/embryo.slc"], False),
    ("render embryo", ["-m", "volviz.cli", "render", "{data}/volumes/embryo.slc", "-o", "{tmp}/e.png"], False),
    ("render bluntfin", ["-m", "volviz.cli", "render", "{data}/bluntfin/bluntfinxyz.bin", "-o", "{tmp}/b.png"], False),
    ("render hydrogen.vti", ["-m", "volviz.cli", "render", "{data}/volumes/hydrogen.vti", "-o", "{tmp}/h.png"], False),
    ("app embryo", ["-m", "volviz_app.main", "--first-frame", "{data}/volumes/embryo.slc"], True),
]
TOP_IMPORTS = 15


@dataclass
class Result:
    name: str
    tree: str = ""
    walls: list[float] = field(default_factory=list)
    cpus: list[float] = field(default_factory=list)
    rss_mb: float = 0.0
    import_s: float = 0.0
    top: list[tuple[str, float]] = field(default_factory=list)


def _cpu() -> float:
    used = resource.getrusage(resource.RUSAGE_CHILDREN)
    return used.ru_utime + used.ru_stime


def _run(argv: list[str], first_frame: bool, tree: str = "") -> tuple[float, float, str]:
    """(seconds from spawn to exit, or to the first frame the app prints; CPU seconds; stderr), with ``tree`` (a
    source tree) first on the path when given."""
    env = {**os.environ, "PYTHONPATH": tree} if tree else None
    start, cpu = time.time(), _cpu()
    done = subprocess.run(argv, capture_output=True, text=True, cwd=tree or REPO, timeout=600, env=env)
    if done.returncode != 0:
        raise RuntimeError(f"{shlex.join(argv)} failed ({done.returncode}): {done.stderr[-2000:]}")
    wall = time.time() - start
    if first_frame:
        line = next(l for l in done.stdout.splitlines() if l.startswith("first frame "))
        wall = float(line.split()[2]) - start
    return wall, _cpu() - cpu, done.stderr


def import_times(stderr: str) -> tuple[float, list[tuple[str, float]]]:
    """``-X importtime`` output -> (sum of the modules' own seconds, [(module, cumulative s)] of the imports started
    outside any other import, largest first)."""
    total, top = 0.0, []
    for line in stderr.splitlines():
        if not line.startswith("import time:") or "self [us]" in line:
            continue
        own, cumulative, name = line[len("import time:"):].split("|")
        total += int(own) / 1e6
        if not name.startswith("  "):   # one space after the bar at depth 0, two more per level
            top.append((name.strip(), int(cumulative) / 1e6))
    return total, sorted(top, key=lambda t: -t[1])


def measure(name: str, argv: list[str], reps: int, first_frame: bool, trees: list[str]) -> list[Result]:
    """One Result per tree (``[""]``: this checkout), the trees' runs alternating."""
    results = [Result(name, tree) for tree in trees]
    for r in results:
        _run(argv, first_frame, r.tree)   # warm-up: the OS's file cache, Numba's cache index
    for _ in range(reps):
        for r in results:
            wall, cpu, _ = _run(argv, first_frame, r.tree)
            r.walls.append(wall)
            r.cpus.append(cpu)
    for r in results:
        with tempfile.NamedTemporaryFile(suffix=".txt") as rss:
            _run(["/usr/bin/time", "-v", "-o", rss.name, *argv], first_frame, r.tree)
            for line in Path(rss.name).read_text().splitlines():
                if "Maximum resident set size" in line:
                    r.rss_mb = int(line.split(":")[1]) / 1024
        r.import_s, r.top = import_times(_run([argv[0], "-X", "importtime", *argv[1:]], first_frame, r.tree)[2])
    return results


def report(results: list[Result], command: str, loads: tuple[str, str]) -> str:
    method = " ".join(__doc__.split("\n\n")[1].split())
    lines = ["# Start-up of fresh processes", "", f"Made by `{command}`. {method}", "",
             f"Load average (1, 5, 15 min) before: {loads[0]}; after: {loads[1]} (2 cores).", "",
             "| case | tree | wall median (min-max) | CPU median | peak RSS | imports (own times summed) |",
             "|---|---|---|---|---|---|"]
    for r in results:
        lines.append(f"| {r.name} | {r.tree or 'this checkout'} | {statistics.median(r.walls):.2f} s "
                     f"({min(r.walls):.2f}-{max(r.walls):.2f}) | {statistics.median(r.cpus):.2f} s | "
                     f"{r.rss_mb:.0f} MB | {r.import_s:.2f} s |")
    for r in results:
        lines += ["", f"Largest imports of *{r.name}*{' in ' + r.tree if r.tree else ''} (cumulative s, imports "
                  "started outside another import):", "",
                  ", ".join(f"`{m}` {s:.2f}" for m, s in r.top[:TOP_IMPORTS])]
    return "\n".join(lines) + "\n"


def _load() -> str:
    return ", ".join(f"{v:.1f}" for v in os.getloadavg())


def main(argv: list[str] | None = None) -> int:
    ap = UsageParser(prog="volviz bench startup", description=__doc__.split("\n\n")[0])
    ap.add_argument("--reps", type=int_in(1, 100), default=5, help="timed runs per case, median (default 5)")
    ap.add_argument("--only", nargs="+", default=None, help="the cases to run, by name (default: all)")
    ap.add_argument("--trees", nargs="+", default=[""], metavar="DIR",
                    help="source trees to compare, run by run (default: this checkout)")
    ap.add_argument("--out", type=Path, default=REPO / "docs" / "bench" / "startup.md")
    args = ap.parse_args(argv)
    data = os.environ.get("VOLVIZ_DATA", str(REPO.parent / "shared" / "data"))
    loads = [_load()]
    results = []
    with tempfile.TemporaryDirectory(prefix="volviz-startup-") as tmp:
        for name, case, display in CASES:
            if args.only and name not in args.only:
                continue
            if display and not os.environ.get("DISPLAY"):
                print(f"{name}: skipped (no DISPLAY; run under xvfb-run)", flush=True)
                continue
            argv_ = [sys.executable] + [c.format(data=data, tmp=tmp) for c in case]
            for r in measure(name, argv_, args.reps, display, args.trees):
                print(f"{name} {r.tree}: {statistics.median(r.walls):.2f} s, CPU {statistics.median(r.cpus):.2f} s, "
                      f"{r.rss_mb:.0f} MB, imports {r.import_s:.2f} s", flush=True)
                results.append(r)
    loads.append(_load())
    command = "volviz bench startup " + " ".join(shlex.quote(a) for a in (argv if argv is not None else sys.argv[1:]))
    atomic_write_text(args.out, report(results, command.strip(), (loads[0], loads[1])))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
