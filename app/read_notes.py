"""The read warnings of the files a scene shows: a ``volviz.io.ReadWarning`` (a file that was read but will likely be
shown other than its author meant, e.g. a CF coordinate the reader takes for data) raised on any thread while the
datasets load is kept by ``READ_NOTES`` until the scene is shown; ``NonFiniteStatus`` then puts it in the status bar.

Warnings reach Python's ``warnings.showwarning`` on the thread that raised them (a background job's); the hook here
keeps the ReadWarnings under a lock and passes every warning on to the handler it replaced (stderr by default)."""
from __future__ import annotations

import threading
import warnings
from pathlib import Path
from typing import Any, Iterable

from volviz.io import ChoiceWarning, ReadWarning


class ReadNotes:
    """ReadWarning messages raised since the last ``take``, and the ``ChoiceWarning``s among them."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._notes: list[str] = []
        self._choices: list[ChoiceWarning] = []

    def install(self) -> None:
        """Hook ``warnings.showwarning`` (once; again after a ``warnings.catch_warnings`` block restored it) and show
        every ReadWarning, not only the first from one place: a file opened again warns again."""
        previous = warnings.showwarning
        if getattr(previous, "read_notes", None) is self:
            return

        def show(message: Any, category: type[Warning], filename: str, lineno: int, file: Any = None,
                 line: str | None = None) -> None:
            if issubclass(category, ReadWarning):
                with self._lock:
                    self._notes.append(str(message))
                    if isinstance(message, ChoiceWarning):
                        self._choices.append(message)
            previous(message, category, filename, lineno, file, line)

        show.read_notes = self  # type: ignore[attr-defined]
        warnings.showwarning = show
        warnings.filterwarnings("always", category=ReadWarning)

    def take(self, paths: Iterable[str] = ()) -> list[str]:
        """The notes kept so far that name one of the files ``paths`` (by file name), without repeats; all are
        forgotten (those of a scene that was replaced before it was shown included)."""
        return self.take_all(paths)[0]

    def take_all(self, paths: Iterable[str] = ()) -> tuple[list[str], list[ChoiceWarning]]:
        """``take``'s notes and the ``ChoiceWarning``s among them (of the same files, in the order raised)."""
        with self._lock:
            notes, self._notes = self._notes, []
            choices, self._choices = self._choices, []
        names = {Path(p).name for p in paths}

        def named(note: str) -> bool:
            return any(name and name in note for name in names)

        return [n for n in dict.fromkeys(notes) if named(n)], [c for c in choices if named(str(c))]


READ_NOTES = ReadNotes()


def short_note(note: str, limit: int = 160) -> str:
    """A ReadWarning for the status bar: the file's name instead of its full path, at most ``limit`` characters."""
    head, sep, rest = note.partition(": ")
    text = f"{Path(head).name}: {rest}" if sep and ("/" in head or "\\" in head) else note
    return text if len(text) <= limit else text[:limit - 1].rstrip() + "…"
