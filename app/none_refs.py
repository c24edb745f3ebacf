"""A guard against a reference-count bug of PySide6 6.12.0 on Python < 3.12: every Qt method that returns nothing
(``setText``, ``update``, ``processEvents``...) takes one reference from ``None`` and never gives it back. An app
starts with about 125,000 references to ``None``; ten thousand ``QLabel.setText`` calls, or a few thousand drags in
the viewport, used them up and the interpreter aborted ("Fatal Python error: none_dealloc"), losing unsaved work.

``None`` is never deallocated in a correct program (from Python 3.12 on it is immortal), so giving it 2^40 more
references at start-up is harmless and puts the crash a trillion calls away. Nothing is done where the bug cannot
occur (Python 3.12 or later, or another PySide6)."""
from __future__ import annotations

import ctypes
import sys

import PySide6

SPARE_REFERENCES = 1 << 40
_added = False


def affected(python: tuple[int, int] = sys.version_info[:2], pyside: str = PySide6.__version__) -> bool:
    """Whether this Python and PySide6 lose references to ``None`` (PySide6 6.12.0, Python before 3.12)."""
    return python < (3, 12) and pyside.split("+")[0] == "6.12.0"


def guard_none_references() -> bool:
    """Add ``SPARE_REFERENCES`` to ``None``'s count once per process where ``affected``; True when it did."""
    global _added
    if _added or not affected():
        return False
    count = ctypes.c_ssize_t.from_address(id(None))   # ob_refcnt, the first field of every CPython object
    count.value += SPARE_REFERENCES
    _added = True
    return True
