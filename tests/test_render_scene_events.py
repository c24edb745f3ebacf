"""Change events of a live scene (``volviz.model.events``, issue #18): each edit of the session's state through the
``SceneController`` is announced once to its subscribers, after the session and the views hold it, in subscription
order; an unsubscribed function hears nothing more; the isosurfaces' mode announces only a change of mode (the
build re-applies the current one)."""
from __future__ import annotations

import numpy as np
import pytest

from volviz.model.events import CHANGE_KINDS, ChangeNotifier, SceneChange


def test_a_change_kind_is_checked_and_subscribers_are_called_in_order():
    with pytest.raises(ValueError, match="unknown change 'colour'"):
        SceneChange("colour")                                    # type: ignore[arg-type]
    notifier = ChangeNotifier()
    heard: list[tuple[str, SceneChange]] = []
    stop_a = notifier.subscribe(lambda c: heard.append(("a", c)))
    notifier.subscribe(lambda c: heard.append(("b", c)))
    notifier.notify(SceneChange("clip"))
    stop_a()
    stop_a()                                                     # twice is harmless
    notifier.notify(SceneChange("opacity", "vol"))
    assert heard == [("a", SceneChange("clip")), ("b", SceneChange("clip")), ("b", SceneChange("opacity", "vol"))]
    assert set(CHANGE_KINDS) == {"visible", "opacity", "transfer_function", "clip", "iso_mode"}


def test_the_controller_announces_each_edit_after_applying_it():
    import pyvista as pv

    from volviz.model.clip import ClipPlane, ClipSettings
    from volviz.model import RegularVolume
    from volviz.render.controller import SceneController
    from volviz.session import CameraState, Component, DatasetRef, Session

    g = np.linspace(-1.0, 1.0, 16)
    x, y, z = np.meshgrid(g, g, g, indexing="ij")
    datasets = {"ball": RegularVolume((x * x + y * y + z * z).astype(np.float32))}
    session = Session(datasets=[DatasetRef("ball", "/unused")],
                      components=[Component("vol", "volume", "ball"),
                                  Component("iso", "isosurface", "ball",
                                            settings={"styles": [{"value": 0.5, "color": [1, 0.5, 0.2],
                                                                  "opacity": 0.5}]})],
                      camera=CameraState((0.0, -6.0, 2.0), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)))
    session.render.options.update(scalar_bar=False, axes=False, outline=False)
    pl = pv.Plotter(off_screen=True, window_size=[64, 48])
    try:
        c = SceneController(pl, session, datasets)
        c.build()
        heard: list[tuple[SceneChange, object]] = []

        def state(change: SceneChange) -> object:          # what a subscriber reads back when it is told
            comp = None if change.component is None else c.component(change.component)
            return {"visible": lambda: comp.visible, "opacity": lambda: comp.opacity,
                    "transfer_function": lambda: list(session.transfer_functions[comp.transfer_function].extinction),
                    "clip": lambda: len(session.clip.planes), "iso_mode": lambda: c.iso_mode}[change.what]()

        c.changes.subscribe(lambda change: heard.append((change, state(change))))
        c.set_visible("vol", False)
        c.set_opacity("vol", 0.25)
        tf = c.transfer_function("vol").scaled_extinction(2.0)
        c.set_transfer_function("vol", tf)
        c.set_clip(ClipSettings(planes=[ClipPlane((0.0, 0.0, 0.0), (1.0, 0.0, 0.0))]))
        c.set_iso_mode("vtk")                                 # the current mode: nothing changed
        c.set_iso_mode("2pass")
        assert heard == [(SceneChange("visible", "vol"), False), (SceneChange("opacity", "vol"), 0.25),
                         (SceneChange("transfer_function", "vol"), list(tf.extinction)),
                         (SceneChange("clip"), 1), (SceneChange("iso_mode"), "2pass")]
    finally:
        pl.close()
