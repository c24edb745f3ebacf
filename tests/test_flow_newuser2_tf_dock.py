"""The transfer-function dock fits its column at the default window sizes (issue #28, found looking at the window as
a new user): at 1280x740 (a 1366x768 laptop) the dock scrolled by 24 pixels and cut its last line, the gestures hint
("... right-click: remove it · double-click: change its color"), and at 1024x572 (a 1024x600 netbook) by 44, because
the histogram canvas would not go below 160 pixels."""
from __future__ import annotations

import pytest
from PySide6.QtWidgets import QScrollArea

from flows import open_settled
from volviz_app.docks.tf_canvas import MIN_HEIGHT


@pytest.mark.parametrize("size", [(1280, 740), (1024, 572)])
def test_the_tf_dock_shows_all_of_its_content_at_the_default_size(qtbot, make_window, size) -> None:
    """ironProt.vtk in a window of the default size on a laptop and on a netbook screen: the dock's scroll area has
    nothing to scroll, and the hint, the info line and the buttons are painted whole."""
    window = open_settled(qtbot, make_window, "volumes/ironProt.vtk", size)
    editor = window.tf_editor
    area = next(a for a in window.tf_dock.findChildren(QScrollArea) if a.widget() is editor)
    assert area.verticalScrollBar().maximum() == 0, area.verticalScrollBar().maximum()   # before: 10 and 24
    for widget in (editor.hint, editor.info, editor.undo_button, editor.export_button, editor.canvas):
        assert widget.visibleRegion().boundingRect() == widget.rect(), widget
    assert editor.canvas.height() >= MIN_HEIGHT
