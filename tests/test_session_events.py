"""The session is the evented model (issue #31): an edit made on the session itself (a script, no Qt) is announced on
``Session.changes``; the installed ``SceneController`` hears it, gives it to its views (which re-make their image)
and passes it on to its own ``changes``, after the views hold it. Real VTK rendering off screen."""
from __future__ import annotations

import copy
import dataclasses

import numpy as np
import pytest

from volviz.model.clip import ClipPlane, ClipSettings
from volviz.model.events import SceneChange
from volviz.session import CameraState, Component, DatasetRef, Session, session_to_dict


def _scene_session() -> tuple[Session, dict]:
    """A PT volume on the CPU (the demo's tetrahedra; a camera view whose image is re-made for an edit, not drawn
    by VTK itself) and a regular volume VTK draws."""
    from volviz.model import RegularVolume

    g = np.linspace(-1.0, 1.0, 16)
    x, y, z = np.meshgrid(g, g, g, indexing="ij")
    datasets = {"ball": RegularVolume((x * x + y * y + z * z).astype(np.float32), origin=(3.0, 0.0, 0.0))}
    session = Session(datasets=[DatasetRef("ball", "/unused")],
                      components=[Component("vol", "demo", settings={"cells_per_edge": 6}),
                                  Component("ball", "volume", "ball")],
                      camera=CameraState((2.0, -9.0, 3.0), (2.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    session.render.options.update(backend="cpu", scalar_bar=False, axes=False, outline=False)
    return session, datasets


def _picture(session: Session, datasets: dict, edit=None) -> tuple[np.ndarray, list, list]:
    """The scene of ``session`` built off screen, ``edit(session)`` made on the session after the build; the frame,
    what the session announced and what the controller passed on."""
    import pyvista as pv

    from volviz.render.controller import SceneController

    pl = pv.Plotter(off_screen=True, window_size=[96, 72])
    try:
        c = SceneController(pl, session, datasets)
        c.build()
        model: list[SceneChange] = []
        views: list[SceneChange] = []
        session.changes.subscribe(model.append)
        c.changes.subscribe(views.append)
        if edit is not None:
            edit(session)
        pl.render()
        return np.asarray(pl.screenshot(None, return_img=True))[..., :3].astype(np.float64), model, views
    finally:
        pl.close()


def test_a_script_edit_of_the_session_re_renders_the_view_it_reaches() -> None:
    session, datasets = _scene_session()
    before, _, _ = _picture(copy.deepcopy(session), datasets)
    from volviz.optics import TransferFunction

    dense = TransferFunction.ramp(0.0, 3.0, 6.0, (1.0, 0.4, 0.1))
    after, model, views = _picture(session, datasets, lambda s: s.set_transfer_function("vol", dense))
    assert model == views == [SceneChange("transfer_function", "vol")]
    assert session.transfer_functions["vol"] is dense and session.components[0].transfer_function == "vol"
    # the view re-made its image for the edit: the frame is the one a scene built with that function shows
    built, _, _ = _picture(copy.deepcopy(session), datasets)
    assert (np.abs(after - before).sum(axis=2) > 30).mean() > 0.05
    assert np.abs(after - built).max() <= 2.0


def test_every_kind_of_edit_is_announced_once_then_passed_on_by_the_controller() -> None:
    session, datasets = _scene_session()
    order: list[str] = []

    def edits(s: Session) -> None:
        s.changes.subscribe(lambda change: order.append(f"model {change.what}"))
        s.set_opacity("vol", 1.7)                          # clamped
        assert s.components[0].opacity == 1.0
        s.set_opacity("vol", 0.4)
        s.set_visible("vol", False)
        s.set_visible("vol", True)
        s.set_clip(ClipSettings(planes=[ClipPlane((0.0, 0.0, 0.0), (2.0, 0.0, 0.0))]))
        s.set_iso_mode("vtk")                              # the current mode: nothing changed, nothing announced
        s.set_iso_mode("2pass")
        with pytest.raises(ValueError, match="unknown isosurface mode 'fast'"):
            s.set_iso_mode("fast")
        with pytest.raises(ValueError, match="clip plane normal must not be zero"):
            s.set_clip({"planes": [{"point": [0, 0, 0], "normal": [0, 0, 0]}], "box": None})

    edited, model, views = _picture(session, datasets, edits)
    expected = [SceneChange("opacity", "vol"), SceneChange("opacity", "vol"), SceneChange("visible", "vol"),
                SceneChange("visible", "vol"), SceneChange("clip"), SceneChange("iso_mode")]
    assert model == views == expected
    assert order == ["model opacity", "model opacity", "model visible", "model visible", "model clip", "model iso_mode"]
    assert session.components[0].opacity == 0.4 and session.components[0].visible
    assert session.clip == ClipSettings(planes=[ClipPlane((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))])   # the normal made unit
    assert session_to_dict(session)["clip"] == {"planes": [{"point": [0.0, 0.0, 0.0], "normal": [1.0, 0.0, 0.0]}],
                                                "box": None}
    assert session.render.options["iso_mode"] == "2pass"
    built, _, _ = _picture(copy.deepcopy(session), datasets)   # the views hold the edits: as built with them
    assert np.abs(edited - built).max() <= 2.0


def test_a_cleared_scene_hears_no_more_edits_and_a_copied_session_no_listeners() -> None:
    import pyvista as pv

    from volviz.render.controller import SceneController

    session, datasets = _scene_session()
    pl = pv.Plotter(off_screen=True, window_size=[32, 24])
    try:
        c = SceneController(pl, session, datasets)
        c.build()
        heard: list[SceneChange] = []
        c.changes.subscribe(heard.append)
        twin = copy.deepcopy(session)                      # a copy of the model, not of the scene listening to it
        twin.set_opacity("vol", 0.5)
        assert heard == [] and session.components[0].opacity == 1.0
        assert twin.components[0].opacity == 0.5 and twin != session
        c.session = twin                                   # another session object for the scene (a File > Save)
        session.set_opacity("vol", 0.75)
        twin.set_opacity("vol", 0.25)
        assert heard == [SceneChange("opacity", "vol")] and c.component("vol").opacity == 0.25
        c.session = session
        heard.clear()
        c.clear()
        session.set_opacity("vol", 0.5)
        assert heard == [] and c.views == {}
    finally:
        pl.close()
    # the notifier is no part of the document: what is saved is unchanged by listeners
    assert "changes" not in session_to_dict(session)


def test_the_session_holds_its_transfer_functions_and_clipping_as_immutable_models() -> None:
    from volviz.optics import TransferFunction

    session, _ = _scene_session()
    assert session.transfer_function("vol") is None and session.clip == ClipSettings()
    tf = TransferFunction.ramp(0.0, 2.0, 3.0)
    session.set_transfer_function("vol", tf)
    assert session.transfer_function("vol") is tf and session.transfer_functions == {"vol": tf}   # no JSON copy
    with pytest.raises(ValueError, match="read-only"):
        tf.extinction[1] = 9.0                                       # a model is edited by making a new one
    clip = ClipSettings(planes=[ClipPlane((0.0, 0.0, 0.0), (0.0, 3.0, 4.0))])
    session.set_clip(clip)
    assert session.clip is clip and clip.planes[0].normal == (0.0, 0.6, 0.8)
    with pytest.raises(dataclasses.FrozenInstanceError):
        clip.box = None                                              # type: ignore[misc]
    twin = copy.deepcopy(session)                                    # immutable: a copy shares the models
    assert twin.transfer_function("vol") is tf and twin.clip == clip and twin == session
