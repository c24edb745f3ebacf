"""``PartAttribute``: a read-only attribute of the main window that is an attribute of one of its parts
(``window.file_dialog`` is ``window.session_files.file_dialog``), for the callers that read it on the window while
they move to the part (``volviz_app.window``'s forwarders)."""
from __future__ import annotations

from typing import Any, Optional


class PartAttribute:
    """``name = PartAttribute("part")`` in a class body: reading ``obj.name`` reads ``obj.part.name`` (or
    ``obj.part.attribute`` when given)."""

    def __init__(self, part: str, attribute: Optional[str] = None) -> None:
        self.part, self.attribute = part, attribute

    def __set_name__(self, owner: type, name: str) -> None:
        if self.attribute is None:
            self.attribute = name

    def __get__(self, obj: Any, owner: Optional[type] = None) -> Any:
        if obj is None:
            return self
        return getattr(getattr(obj, self.part), str(self.attribute))
