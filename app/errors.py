"""Error messages in the user's terms: which file, what is wrong with it, what to do about it.

volviz's own errors (``ReadError``, ``SessionError``, ``SceneError``) are written for users and are quoted; any other
exception is a fault of volviz, not of the file: the user gets a plain sentence and the details go to the log. A
message never shows a traceback, an exception's class name, or the name of an internal temporary file.
"""
from __future__ import annotations

import logging
import os
import re
from pathlib import Path
from typing import Optional

log = logging.getLogger("volviz.app")

# volviz's own temporaries: the atomic writers' ``.NAME.volviz-tmp-PID-RANDOM`` (and older ``.partial`` names) and
# the working folders it makes in the temporary directory (``volviz-...``, ``vvs-part...``); a user's own file in
# /tmp is named as it is
_TEMPORARY = re.compile(r"[^\s:]*(?:\.volviz-tmp-[^\s:]*|\.partial\b|/volviz-[\w.-]*/|/vvs-part[\w.-]*/)[^\s:]*")


def hide_temporary_names(text: str) -> str:
    """``text`` with volviz's internal temporary file names replaced by words (see ``_TEMPORARY``)."""
    return _TEMPORARY.sub("a temporary file", text)


def _problem(exc: BaseException, path: Optional[Path]) -> Optional[str]:
    """What volviz's own error says is wrong, without the path it starts with; None for any other exception."""
    from volviz.io.errors import ReadError
    from volviz.scene.errors import SceneError
    from volviz.session import SessionError

    if isinstance(exc, ReadError):
        return exc.problem
    if isinstance(exc, (SessionError, SceneError)):
        text = str(exc)
        if path is not None:
            for prefix in (str(path), str(path.resolve()), path.name):
                if text.startswith(prefix + ": "):
                    text = text[len(prefix) + 2:]
        return text
    return None


def open_error(path: Optional[str | os.PathLike], exc: BaseException, what: str = "") -> str:
    """The message of a failed open of ``path`` (or of the scene ``what`` when there is no file): three parts, the
    file, what is wrong, what to do."""
    p = Path(path) if path is not None else None
    name = f"“{p.name}”" if p is not None else (what or "the scene")
    where = f" (in {p.parent})" if p is not None and str(p.parent) not in ("", ".") else ""
    if isinstance(exc, FileNotFoundError) or (p is not None and not p.exists()):
        return (f"volviz cannot open {name}{where}: it does not exist.\n\n"
                "It may have been moved, renamed or deleted. Open it from where it is now (File > Open Data).")
    if isinstance(exc, PermissionError):
        return (f"volviz cannot open {name}{where}: it may not be read (permission denied).\n\n"
                "Ask the file's owner for read access, or copy it to a folder of yours.")
    if isinstance(exc, MemoryError):
        return (f"volviz cannot open {name}{where}: it needs more memory than is free.\n\n"
                "Close other programs, or open a smaller part of the data.")
    problem = _problem(exc, p)
    if problem is None:
        log.error("opening %s failed", p or what, exc_info=(type(exc), exc, exc.__traceback__))
        return (f"volviz cannot show {name}{where}: its content is of a kind volviz does not handle yet.\n\n"
                "Check that it is a complete file of the type its name says. The details are in the log; please "
                "report them with the file.")
    kind = "session" if p is not None and p.suffix.lower() == ".json" else "file"
    advice = (getattr(exc, "advice", None) or
              ("Check the field named above in the session file, or open the data file itself."
               if kind == "session" else
               "Check that the file is complete (a download or copy may have stopped early) and of the type its "
               "name says; File > Open Data lists the types volviz reads."))
    if advice[:1].islower():
        advice = advice[0].upper() + advice[1:] + "."
    return f"volviz cannot open {name}{where}:\n{hide_temporary_names(problem)}\n\n{advice}"
