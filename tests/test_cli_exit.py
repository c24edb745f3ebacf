"""Issue #30, time to the first image: the ``volviz`` program collects its garbage as a program
(``volviz.cli._as_program``): a larger first generation while it runs, and at its exit no last passes
(``_no_collection_at_exit`` freezes every object still alive once the other exit handlers have run); a caller of
``volviz.cli.main(argv)`` in its own process keeps its collector as it was."""
from __future__ import annotations

import subprocess
import sys

from conftest import REPO

#: runs ``volviz --version`` as the program (``main()``, reading ``sys.argv``) or in-process (``main(argv)``), and
#: prints, from an exit handler registered before ``main`` (so it runs after main's own), how many objects the
#: collector has frozen at the exit and its first generation's threshold
CHILD = """
import atexit, gc, sys
from volviz.cli import main
atexit.register(lambda: print("frozen at exit", gc.get_freeze_count(), flush=True))
atexit.register(lambda: print("threshold", gc.get_threshold()[0], flush=True))
if sys.argv[1] == "program":
    sys.argv = ["volviz", "--version"]
    code = main()
else:
    code = main(["--version"])
print("code", code, flush=True)
"""


def _exit_report(mode: str) -> tuple[int, int, int]:
    done = subprocess.run([sys.executable, "-c", CHILD, mode], cwd=REPO, capture_output=True, text=True,
                          timeout=120)
    assert done.returncode == 0, done.stderr[-3000:]
    lines = dict(line.rsplit(" ", 1) for line in done.stdout.splitlines()
                 if line.startswith(("code", "frozen", "threshold")))
    return int(lines["code"]), int(lines["frozen at exit"]), int(lines["threshold"])


def test_the_program_collects_less_often_and_not_at_its_exit() -> None:
    code, frozen, threshold = _exit_report("program")
    assert code == 0
    assert frozen > 1_000      # every object alive: the interpreter's and volviz's modules at least
    assert threshold == 10_000


def test_a_caller_in_process_keeps_its_collector() -> None:
    assert _exit_report("in-process") == (0, 0, 700)       # Python's own threshold
