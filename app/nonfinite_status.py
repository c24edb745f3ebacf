"""The status bar's one note on the data shown: once a scene is shown, the read warnings of its files
(``read_notes``) and the arrays of its datasets that hold NaN or Inf values, named with their counts ("Showing x.vti —
12 non-finite values in density (drawn transparent)"); the full warnings are in the status bar's tooltip.

The counts are ``volviz.model.arrays.list_arrays``'s, computed in the background (a large float volume takes a
while to scan); the note appears when they arrive, and only if the same scene is still shown."""
from __future__ import annotations

from typing import Any

from volviz.jobs import JobOutcome
from .read_notes import READ_NOTES, short_note


def nonfinite_note(datasets: dict[str, Any]) -> str:
    """``"12 non-finite values in density; 3 in p (drawn transparent)"``, or ``""`` when every value is finite.
    Datasets without named arrays (height maps, LOD trees) add nothing."""
    from volviz.model.arrays import list_arrays

    counts: list[tuple[str, int]] = []
    for dataset in datasets.values():
        try:
            infos = list_arrays(dataset)
        except (TypeError, ValueError, AttributeError):  # a dataset kind that lists no arrays
            continue
        counts += [(info.name, info.nonfinite) for info in infos if info.nonfinite]
    if not counts:
        return ""
    (first, n), rest = counts[0], counts[1:]
    parts = [f"{n:,} non-finite values in {first}"] + [f"{m:,} in {name}" for name, m in rest]
    return "; ".join(parts) + " (drawn transparent)"


class NonFiniteStatus:
    """Appends the read warnings and ``nonfinite_note`` of the shown scene's datasets to ``window.status_label``
    (``window`` provides ``controller``, ``datasets``, ``jobs``, ``status_label`` and ``file_choices``, which is
    given the files' choices of what to show). ``note`` is the last note
    shown, ``warnings`` the read warnings of the scene shown."""

    def __init__(self, window: Any) -> None:
        self.window = window
        self.note = ""
        self.warnings: list[str] = []
        READ_NOTES.install()

    def report(self, title: str) -> None:
        """The scene titled ``title`` is shown: count its non-finite values in the background, then say so once."""
        window = self.window
        controller, datasets = window.controller, dict(window.datasets)
        READ_NOTES.install()  # again, should a ``warnings.catch_warnings`` block have restored the handler
        paths = [ref.path for ref in controller.session.datasets] if controller is not None else []
        self.warnings, choices = READ_NOTES.take_all(paths)
        window.file_choices.set_choices(choices)
        hint = [window.file_choices.hint()] if window.file_choices.choices else []
        read = "; ".join(hint + [short_note(n) for n in self.warnings])
        self.note = read
        window.status_label.setToolTip("\n\n".join(self.warnings))
        if read:
            window.status_label.setText(f"Showing {title} — {read}")

        def count(progress: Any = None) -> str:
            return nonfinite_note(datasets)

        def done(outcome: JobOutcome) -> None:
            if outcome.error is not None or not outcome.result or window.controller is not controller:
                return
            self.note = "; ".join(n for n in (read, str(outcome.result)) if n)
            window.status_label.setText(f"Showing {title} — {self.note}")

        window.jobs.submit(count, name="count non-finite values", key="nonfinite", on_done=done)
