"""The set-up of a prepared scene's CPU ray-cast volumes as a background job of the window, before they are
installed (``volviz.render.volume_setup``: the empty-space volume and gradients their first render made on the GUI
thread, issue #28). One way for every path that installs volumes: a scene's loading (``scene_loading``) and a
component hidden at load and shown later (``scene_edits.show_component``)."""
from __future__ import annotations

import logging
from typing import TYPE_CHECKING, Callable, Optional

from volviz.jobs import Job, JobOutcome

if TYPE_CHECKING:
    from volviz.render.controller import SceneController
    from volviz.render.scene_builder import PreparedScene
    from .workers import JobBridge

log = logging.getLogger("volviz_app.window")


def set_up_volumes(jobs: JobBridge, controller: SceneController, prepared: PreparedScene, title: str,
                   then: Callable[[bool], None]) -> Optional[Job]:
    """GUI thread: ``then(cancelled)`` once the volumes that VTK's CPU ray caster will draw for ``prepared`` are set
    up on the process's set-up window's thread (``volume_setup.shared_setup``, made and primed at start-up), at once
    where there are none. A failed set-up is logged and the volumes installed all the same (their first render makes
    what it would have made). Returns the set-up's job (None: none)."""
    try:
        volumes = controller.volumes_to_set_up(prepared)
    except Exception:   # (the install makes them again, and says what is wrong)
        log.exception("making the volumes of %s failed", title)
        volumes = []
    if not volumes:
        then(False)
        return None
    from volviz.render.volume_setup import shared_setup   # (made and primed at start-up: startup_imports)

    setup = shared_setup()
    ticket = setup.hold(volumes)
    del volumes

    def done(outcome: JobOutcome) -> None:
        setup.release(ticket)
        if outcome.error is not None:
            log.warning("setting up the volumes of %s failed: %s", title, outcome.error)
        then(outcome.cancelled)

    return jobs.submit(setup.run, ticket, name=f"set up the volumes of {title}", on_done=done)
