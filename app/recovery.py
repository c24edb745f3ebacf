"""Crash-recovery files, one per window: ``recovery-PID-RANDOM.json`` in the recovery folder.

Each window autosaves to its own file and deletes only its own file when it closes cleanly, so two windows (in one
process or in two) never overwrite or delete each other's autosave. A file whose owner process ``PID`` is no longer
running was left by a crash: it is *orphaned*, and a window offers to recover it after claiming it with an atomic
rename to its own file name (of two windows offering at once, exactly one gets each orphaned file).
"""
from __future__ import annotations

import os
import re
import secrets
from pathlib import Path

from volviz.io.atomic import process_alive

_NAME = re.compile(r"\Arecovery(?:-(?P<pid>\d+)-[0-9a-f]+)?\.json\Z")


def window_file(directory: Path) -> Path:
    """A recovery file name of its own for a new window of this process."""
    return Path(directory) / f"recovery-{os.getpid()}-{secrets.token_hex(4)}.json"


def orphaned(directory: Path) -> list[Path]:
    """Recovery files in ``directory`` whose owner process is gone, newest first (``recovery.json`` of volviz
    versions before per-window files counts as orphaned)."""
    try:
        entries = list(Path(directory).iterdir())
    except OSError:
        return []
    found = []
    for path in entries:
        m = _NAME.match(path.name)
        if m and (m["pid"] is None or not process_alive(int(m["pid"]))):
            try:
                found.append((path.stat().st_mtime, path))
            except OSError:  # claimed by another window meanwhile
                continue
    return [path for _, path in sorted(found, reverse=True)]


def claim(orphan: Path, own: Path) -> bool:
    """Take over ``orphan`` as the window's own recovery file ``own``; False if another window claimed it first."""
    try:
        os.rename(orphan, own)
    except OSError:
        return False
    return True
