"""Opening files through the real Open dialog (issue #28)."""
from __future__ import annotations

from conftest import data_file
from flows import wait_loaded


def test_open_dialog_shows_the_plot3d_solution_beside_its_grid(qtbot, make_window) -> None:
    """File > Open Data asks for a PLOT3D grid and its solution: both are listed under the default filter and under
    the PLOT3D one (the solution file was hidden), and choosing both opens the pair."""
    from PySide6.QtCore import QDir

    window = make_window()
    window.action_open_data.trigger()
    dialog = window.file_dialog
    folder = data_file("bluntfin/bluntfinq.bin").parent
    dialog.setDirectory(str(folder))
    for name_filter in (dialog.nameFilters()[0], next(f for f in dialog.nameFilters() if f.startswith("PLOT3D"))):
        dialog.selectNameFilter(name_filter)
        patterns = name_filter[name_filter.index("(") + 1:-1].split()
        listed = QDir(str(folder)).entryList(patterns, QDir.Filter.Files)
        assert {"bluntfinxyz.bin", "bluntfinq.bin"} <= set(listed), (name_filter[:40], listed)
    dialog.selectFile('"bluntfinxyz.bin" "bluntfinq.bin"')
    dialog.accept()
    wait_loaded(qtbot, window)
    assert window.error_dialog is None and window.session.datasets[0].options.get("q")



def test_a_first_open_that_fails_leaves_the_viewport_in_the_scenes_background(qtbot, make_window, tmp_path) -> None:
    """``volviz-app --screenshot out.png bad.vti``: the error names the file, and the viewport, with no scene yet, is
    drawn in a scene's background colour (it was pyvista's white)."""
    from PySide6.QtGui import QImage, QPixmap
    from PySide6.QtWidgets import QApplication

    from volviz_app.smoke import screenshot

    bad, out = tmp_path / "bad.vti", tmp_path / "out.png"
    bad.write_text("not a volume\n")
    window = make_window()
    assert screenshot(QApplication.instance(), window, str(bad), out) == 1   # 1: the open failed
    image = QImage(str(out))
    viewport = window.plotter.interactor
    centre = viewport.mapTo(window, viewport.rect().center())
    color = image.pixelColor(centre.x(), centre.y())
    expected = [round(255 * c) for c in window.session.render.background]
    # a 16-bit X screen (the tests' Xvfb) keeps 5 or 6 bits of a channel: 26 of 255 shows as 24
    off = 0 if QPixmap.defaultDepth() >= 24 else 7
    got = [color.red(), color.green(), color.blue()]
    assert all(abs(a - b) <= off for a, b in zip(got, expected)), (color.name(), expected, QPixmap.defaultDepth())
