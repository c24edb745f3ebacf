"""PLOT3D pairs in the app, under Xvfb: a grid and its solution chosen together in the Open dialog open as one
dataset, and a solution file opened alone opens with the grid named like it."""
from __future__ import annotations

from conftest import data_file
from test_app_window import wait_loaded, window  # noqa: F401  (the fixture)
from volviz_app.window import MainWindow


def _shown_arrays(window: MainWindow) -> list[str]:
    from volviz.model.arrays import list_arrays

    return [info.name for info in list_arrays(window.datasets["data"])]


def test_grid_and_solution_chosen_together_in_the_open_dialog(qtbot, window: MainWindow) -> None:
    grid, solution = data_file("bluntfin/bluntfinxyz.bin"), data_file("bluntfin/bluntfinq.bin")
    window._ask_open_data()
    dialog = window.file_dialog
    dialog.setDirectory(str(grid.parent))
    dialog.selectFile(f'"{solution.name}" "{grid.name}"')          # the solution first: the order does not matter
    dialog.accept()
    wait_loaded(qtbot, window)
    assert window.session.datasets[0].path == str(grid.resolve())
    assert window.session.datasets[0].options == {"q": str(solution.resolve())}
    assert _shown_arrays(window)[:3] == ["Density", "Momentum", "StagnationEnergy"]


def test_a_solution_file_opened_alone_opens_with_its_grid(qtbot, window: MainWindow) -> None:
    window.open_path(data_file("bluntfin/bluntfinq.bin"))
    wait_loaded(qtbot, window)
    assert window.session.datasets[0].path.endswith("bluntfinxyz.bin")
    assert "Density" in _shown_arrays(window)


def test_a_solution_file_without_its_grid_says_what_to_do(qtbot, window: MainWindow, tmp_path) -> None:
    lonely = tmp_path / "lonelyq.bin"
    lonely.write_bytes(data_file("bluntfin/bluntfinq.bin").read_bytes())
    window.open_path(lonely)
    qtbot.waitUntil(lambda: window.error_dialog is not None and window.error_dialog.isVisible(), timeout=10_000)
    text = window.error_dialog.text()
    assert "lonelyq.bin" in text and "PLOT3D solution" in text and "grid" in text
