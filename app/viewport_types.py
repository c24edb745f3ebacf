"""The viewport's type: pyvistaqt's ``QtInteractor`` or the native-window ``NativeViewport`` (issue #28,
``window.make_plotter`` chooses). Both are a pyvista plotter and a Qt widget (``interactor``), so the window's parts
use either through this one name, and mypy checks what they use on both."""
from __future__ import annotations

from typing import TYPE_CHECKING, TypeAlias, Union

if TYPE_CHECKING:
    from pyvistaqt import QtInteractor

    from .native_viewport import NativeViewport

Viewport: TypeAlias = Union["QtInteractor", "NativeViewport"]
