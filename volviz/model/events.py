"""Change events of a scene (issues #18, #31): what an edit changed in a ``volviz.session.Session``, announced by the
session itself (``Session.changes``) whoever made the edit (a dock, an undo step, a script); the render controller
adapts each to its views and passes it on (``SceneController.changes``), and the app's window refreshes its views on
it instead of being told by each caller. Qt-free: subscribers are plain callables, called on the thread that made
the change, in the order they subscribed. A copy of a model has no subscribers (``copy.deepcopy(session)`` never
copies the views and windows that listen to the original)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Literal, Optional, get_args

__all__ = ["CHANGE_KINDS", "ChangeKind", "ChangeNotifier", "SceneChange"]

#: what can change: a component's visibility, opacity or transfer function, the scene-wide clipping, the isosurfaces'
#: transparency mode
ChangeKind = Literal["visible", "opacity", "transfer_function", "clip", "iso_mode"]
CHANGE_KINDS: tuple[str, ...] = get_args(ChangeKind)


@dataclass(frozen=True)
class SceneChange:
    """One change: ``what`` changed (``ChangeKind``), of ``component`` (None for a scene-wide change); ``preview``: an
    edit under way (a transfer-function point being dragged), which a view may show as a cheaper preview."""

    what: ChangeKind
    component: Optional[str] = None
    preview: bool = False

    def __post_init__(self) -> None:
        if self.what not in CHANGE_KINDS:
            raise ValueError(f"unknown change {self.what!r}; choose from {CHANGE_KINDS}")


class ChangeNotifier:
    """Calls its subscribers with each ``SceneChange`` (``notify``), in subscription order; ``subscribe`` returns the
    function that unsubscribes. A subscriber's exception reaches the code that made the change, after the change."""

    def __init__(self) -> None:
        self._subscribers: list[Callable[[SceneChange], None]] = []

    def subscribe(self, fn: Callable[[SceneChange], None]) -> Callable[[], None]:
        self._subscribers.append(fn)

        def unsubscribe() -> None:
            if fn in self._subscribers:
                self._subscribers.remove(fn)

        return unsubscribe

    def __copy__(self) -> ChangeNotifier:
        return ChangeNotifier()

    def __deepcopy__(self, memo: dict[int, object]) -> ChangeNotifier:
        return ChangeNotifier()

    def notify(self, change: SceneChange) -> None:
        for fn in list(self._subscribers):
            fn(change)
