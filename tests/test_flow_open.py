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
