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
reported before and after, and the 1-minute load at each case's start: the numbers are only comparable within one
run.

With ``--files`` the cases are ``volviz render FILE -o x.png`` (1024x768) of every file ``volviz bench first_open``
opens (``volviz.bench.first_open.opened_files``, those under its 100 MB) instead: the time to the first image of
each (issue #30, target under 5 s), measured as above but without the memory and import runs; a file volviz
refuses is listed as refused.
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
    load: float = 0.0        # 1-minute load average at the case's start
    refused: str = ""        # the last line of a run that failed (a file volviz refuses)
    top: list[tuple[str, float]] = field(default_factory=list)


class RunFailed(RuntimeError):
    """A timed command exited non-zero; ``last`` is the last line of its stderr (volviz's one-line error)."""

    def __init__(self, message: str, last: str) -> None:
        super().__init__(message)
        self.last = last


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
        last = (done.stderr.strip().splitlines() or [""])[-1]
        raise RunFailed(f"{shlex.join(argv)} failed ({done.returncode}): {done.stderr[-2000:]}", last)
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


def measure(name: str, argv: list[str], reps: int, first_frame: bool, trees: list[str],
            extras: bool = True) -> list[Result]:
    """One Result per tree (``[""]``: this checkout), the trees' runs alternating; without ``extras`` no memory and
    import runs; a case whose warm-up fails in a tree is returned with ``refused`` set and no runs."""
    load = os.getloadavg()[0]
    results = [Result(name, tree, load=load) for tree in trees]
    for r in results:
        try:
            _run(argv, first_frame, r.tree)   # warm-up: the OS's file cache, Numba's cache index
        except RunFailed as exc:
            r.refused = exc.last or "failed"
    if any(r.refused for r in results):
        return results
    for _ in range(reps):
        for r in results:
            wall, cpu, _ = _run(argv, first_frame, r.tree)
            r.walls.append(wall)
            r.cpus.append(cpu)
    for r in results if extras else []:
        with tempfile.NamedTemporaryFile(suffix=".txt") as rss:
            _run(["/usr/bin/time", "-v", "-o", rss.name, *argv], first_frame, r.tree)
            for line in Path(rss.name).read_text().splitlines():
                if "Maximum resident set size" in line:
                    r.rss_mb = int(line.split(":")[1]) / 1024
        r.import_s, r.top = import_times(_run([argv[0], "-X", "importtime", *argv[1:]], first_frame, r.tree)[2])
    return results


def report(results: list[Result], command: str, loads: tuple[str, str]) -> str:
    method = " ".join(" ".join(__doc__.split("\n\n")[i].split()) for i in (1, 2))
    lines = ["# Start-up of fresh processes", "", f"Made by `{command}`. {method}", "",
             f"Load average (1, 5, 15 min) before: {loads[0]}; after: {loads[1]} ({os.cpu_count()} cores).", "",
             "| case | tree | load | wall median (min-max) | CPU median | peak RSS | imports (own times summed) |",
             "|---|---|---|---|---|---|---|"]
    for r in results:
        if r.refused:
            lines.append(f"| {r.name} | {r.tree or 'this checkout'} | {r.load:.1f} | refused: "
                         f"{r.refused.replace('|', '/')[:200]} | | | |")
            continue
        rss = f"{r.rss_mb:.0f} MB" if r.rss_mb else ""
        imports = f"{r.import_s:.2f} s" if r.top else ""
        lines.append(f"| {r.name} | {r.tree or 'this checkout'} | {r.load:.1f} | {statistics.median(r.walls):.2f} s "
                     f"({min(r.walls):.2f}-{max(r.walls):.2f}) | {statistics.median(r.cpus):.2f} s | "
                     f"{rss} | {imports} |")
    for r in (r for r in results if r.top):
        lines += ["", f"Largest imports of *{r.name}*{' in ' + r.tree if r.tree else ''} (cumulative s, imports "
                  "started outside another import):", "",
                  ", ".join(f"`{m}` {s:.2f}" for m, s in r.top[:TOP_IMPORTS])]
    return "\n".join(lines) + "\n"


def file_cases(data: Path) -> list[tuple[str, list[str], bool]]:
    """``render NAME`` of every file under ``data`` that ``volviz bench first_open`` opens (under its size limit)."""
    # first_open (its file list and size limit): only with --files
    from volviz.bench.first_open import MAX_MB, opened_files

    cases = []
    for path in opened_files(data):
        size = sum(p.stat().st_size for p in path.rglob("*") if p.is_file()) if path.is_dir() else path.stat().st_size
        if size < MAX_MB * 1e6:
            cases.append((f"render {path.relative_to(data).as_posix()}",
                          ["-m", "volviz.cli", "render", str(path), "-o", "{tmp}/f.png"], False))
    return cases


def _load() -> str:
    return ", ".join(f"{v:.1f}" for v in os.getloadavg())


def main(argv: list[str] | None = None) -> int:
    ap = UsageParser(prog="volviz bench startup", description=__doc__.split("\n\n")[0])
    ap.add_argument("--reps", type=int_in(1, 100), default=5, help="timed runs per case, median (default 5)")
    ap.add_argument("--only", nargs="+", default=None, help="the cases to run, by name (default: all)")
    ap.add_argument("--trees", nargs="+", default=[""], metavar="DIR",
                    help="source trees to compare, run by run (default: this checkout)")
    ap.add_argument("--files", action="store_true",
                    help="time `volviz render FILE` of every file `volviz bench first_open` opens instead")
    ap.add_argument("--out", type=Path, default=REPO / "docs" / "bench" / "startup.md")
    args = ap.parse_args(argv)
    data = str(Path(os.environ.get("VOLVIZ_DATA", REPO.parent / "shared" / "data")).resolve())  # trees run elsewhere
    loads = [_load()]
    results = []
    with tempfile.TemporaryDirectory(prefix="volviz-startup-") as tmp:
        for name, case, display in (file_cases(Path(data)) if args.files else CASES):
            if args.only and name not in args.only:
                continue
            if display and not os.environ.get("DISPLAY"):
                print(f"{name}: skipped (no DISPLAY; run under xvfb-run)", flush=True)
                continue
            argv_ = [sys.executable] + [c.format(data=data, tmp=tmp) for c in case]
            for r in measure(name, argv_, args.reps, display, args.trees, extras=not args.files):
                print(f"{name} {r.tree}: " + (f"refused: {r.refused}" if r.refused else
                      f"{statistics.median(r.walls):.2f} s, CPU {statistics.median(r.cpus):.2f} s" +
                      ("" if args.files else f", {r.rss_mb:.0f} MB, imports {r.import_s:.2f} s")), flush=True)
                results.append(r)
    loads.append(_load())
    command = "volviz bench startup " + " ".join(shlex.quote(a) for a in (argv if argv is not None else sys.argv[1:]))
    atomic_write_text(args.out, report(results, command.strip(), (loads[0], loads[1])))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
