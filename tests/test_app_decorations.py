"""View > Scalar Bar, Orientation Axes and Outline Box under Xvfb: each switches its decoration off and on, and the
choice is saved with the session."""
from __future__ import annotations

from pathlib import Path

from conftest import data_file
from test_app_window import wait_loaded, window  # noqa: F401  (the fixture)
from volviz_app.window import MainWindow


def shown(window: MainWindow) -> dict[str, bool]:
    from volviz.render.decorations import OUTLINE_NAME, scalar_bar_actor

    axes = getattr(window.plotter.renderer, "axes_widget", None)
    return {"scalar_bar": scalar_bar_actor(window.plotter) is not None,
            "axes": bool(axes is not None and axes.GetEnabled()),
            "outline": OUTLINE_NAME in window.plotter.renderer.actors}


def test_view_toggles_switch_decorations_and_are_saved(qtbot, window: MainWindow, tmp_path: Path) -> None:
    from volviz.session import load

    window.open_path(data_file("volumes/neghip.slc"))
    wait_loaded(qtbot, window)
    actions = window.decorations.actions
    assert all(a.isChecked() for a in actions.values())
    assert shown(window) == {"scalar_bar": True, "axes": True, "outline": True}
    view_menu = next(a.menu() for a in window.menuBar().actions() if a.text() == "&View")
    assert all(a in view_menu.actions() for a in actions.values())

    for key in ("scalar_bar", "axes", "outline"):
        actions[key].trigger()
        assert not shown(window)[key] and window.session.render.options[key] is False
    assert window.dirty
    actions["axes"].trigger()
    assert shown(window) == {"scalar_bar": False, "axes": True, "outline": False}

    session_file = tmp_path / "plain.json"
    assert window.save_session(session_file)
    options = load(session_file).render.options
    assert (options["scalar_bar"], options["axes"], options["outline"]) == (False, True, False)
    window.open_path(data_file("volumes/neghip.slc"))   # the defaults again
    wait_loaded(qtbot, window)
    assert all(a.isChecked() for a in actions.values()) and all(shown(window).values())
    window.open_path(session_file)
    wait_loaded(qtbot, window)
    assert [actions[k].isChecked() for k in ("scalar_bar", "axes", "outline")] == [False, True, False]
    assert shown(window) == {"scalar_bar": False, "axes": True, "outline": False}
