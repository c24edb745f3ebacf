"""The per-volume set-up of VTK's CPU ray caster made off the GUI thread, before the volume is shown (issue #28: no
event-loop stall over 100 ms).

VTK's CPU ray caster (vtkFixedPointVolumeRayCastMapper, the smart mapper's RayCast mode: volviz's regular volumes on
a software OpenGL) makes what it keeps per volume in the first render of a new input: the min-max volume it leaps
empty space with and, for a lit volume, the gradients. That render ran on the GUI thread, in the first frame (or
strip) of the scene. Here a new volume, made on the GUI thread and in no renderer yet, is rendered once at 8 x 8
pixels in an offscreen window of a thread of its own (``volviz.render.gl_thread``), with the camera fitted to it;
its OpenGL resources in that window are released after. The mapper keeps what it made, so its first render in the
app's window finds it made and the picture is the same (tests/test_volume_setup.py).

The GUI thread makes the VTK objects and keeps them (``hold``) until it ``release``s them after ``run``: the thread
that runs ``run`` (a worker waiting for the window's thread) and the window's thread only call their methods and
never drop the last reference (``volviz.jobs``: a worker that makes or drops a VTK object can deadlock a render).
While held, nothing else may use the volumes. Making an OpenGL window holds the GIL (the GUI thread's event loop
with it), so the process has one set-up window (``shared_setup``), made at an app window's start-up
(``acquire_shared``) and closed with the last (``release_shared``).
"""
from __future__ import annotations

import itertools
import threading
from typing import TYPE_CHECKING, Any, Optional, Sequence

from volviz.render.gl_thread import GLThread

if TYPE_CHECKING:   # type-only imports for the signatures
    from volviz.jobs import ProgressCallback
    from volviz.render.vtk_facade import vtkRenderer, vtkVolume

__all__ = ["SETUP_SIZE", "VolumeSetup", "acquire_shared", "cpu_ray_cast", "release_shared", "shared_setup"]

SETUP_SIZE = 8   # pixels each way of the render that makes the set-up: its rays cost nothing to speak of


def cpu_ray_cast(volume: vtkVolume) -> bool:
    """Whether VTK's CPU ray caster draws ``volume`` (a smart mapper asked for RayCast, or the fixed-point mapper)."""
    mapper: Any = volume.GetMapper()     # (a vtkSmartVolumeMapper is asked what it was asked for)
    if mapper is None:
        return False
    if mapper.IsA("vtkSmartVolumeMapper"):
        return bool(mapper.GetRequestedRenderMode() == mapper.RayCastRenderMode)
    return bool(mapper.IsA("vtkFixedPointVolumeRayCastMapper"))


class VolumeSetup:
    """One window's thread that sets up the CPU ray caster's new volumes (module docstring). ``hold`` (GUI thread)
    keeps volumes and gives a ticket; ``run(ticket)`` (any thread) renders them once there; ``release(ticket)`` (GUI
    thread, after ``run`` returned) drops them. ``gl`` is the window's thread (its ``threads`` and ``calls``)."""

    def __init__(self) -> None:
        self.gl = GLThread("volviz-volume-setup")
        self._held: dict[int, list[tuple[Any, Any]]] = {}
        self._tickets = itertools.count(1)
        self._lock = threading.Lock()          # the held volumes (the window's thread reads them)
        self._state = threading.Lock()         # closing, and a run queued before it
        self.closed = False

    def hold(self, volumes: Sequence[vtkVolume]) -> int:
        """GUI thread: keep ``volumes`` (in no renderer, used by nothing else until released) for ``run``; their
        mappers are kept too, so that the window's thread finds their Python objects made."""
        ticket = next(self._tickets)
        with self._lock:
            self._held[ticket] = [(v, v.GetMapper()) for v in volumes if cpu_ray_cast(v)]
        return ticket

    def run(self, ticket: int, progress: Optional[ProgressCallback] = None) -> int:
        """Any thread (a background job): render the held volumes of ``ticket`` once on the window's thread; returns
        how many were set up."""
        with self._state:
            if self.closed:
                return 0
            done = self.gl.submit(_set_up, self._held, self._lock, ticket)
        return int(done.result())

    def release(self, ticket: int) -> None:
        """GUI thread: drop the volumes of ``ticket`` (after its ``run`` returned, or when it never ran)."""
        with self._lock:
            self._held.pop(ticket, None)

    def prime(self) -> None:
        """Make the window and its OpenGL context now (the caller waits): at start-up, not in a scene's loading."""
        self.gl.call(_initialize)

    def close(self) -> None:
        """End the thread and close the window (and its X connection) after the runs queued; later runs do nothing."""
        with self._state:
            self.closed = True
            self.gl.close()


_shared: list[VolumeSetup] = []
_users = [0]
_shared_lock = threading.Lock()


def shared_setup() -> VolumeSetup:
    """The process's one ``VolumeSetup`` (module docstring), made at the first call after the last was closed."""
    with _shared_lock:
        if not _shared:
            _shared.append(VolumeSetup())
        return _shared[0]


def acquire_shared() -> VolumeSetup:
    """``shared_setup`` for one more user (an app window), primed (``prime``): the caller ``release_shared``s it."""
    setup = shared_setup()
    with _shared_lock:
        _users[0] += 1
    setup.prime()
    return setup


def release_shared() -> None:
    """One user less; the last one closes the window: an X connection left open when the X server goes first made
    Xlib's fatal I/O error at the process's exit (tests/test_native_viewport_in_process.py)."""
    with _shared_lock:
        _users[0] = max(0, _users[0] - 1)
        ended = _shared.pop() if _shared and _users[0] == 0 else None
    if ended is not None:
        ended.close()


def _initialize(ren: vtkRenderer) -> None:
    ren.GetRenderWindow().Initialize()


def _set_up(ren: vtkRenderer, held: dict[int, list[tuple[Any, Any]]], lock: threading.Lock, ticket: int) -> int:
    """On the window's thread: render the volumes held under ``ticket`` once, then take them out of the window and
    release their OpenGL resources there (the app's window makes its own)."""
    with lock:
        pairs = list(held.get(ticket, ()))
    if not pairs:
        return 0
    window = ren.GetRenderWindow()
    for volume, _ in pairs:
        ren.AddVolume(volume)
    try:
        ren.ResetCamera()              # a volume out of the view is culled: its mapper would not render
        window.SetSize(SETUP_SIZE, SETUP_SIZE)
        window.Render()
    finally:
        for volume, mapper in pairs:
            ren.RemoveVolume(volume)
            mapper.ReleaseGraphicsResources(window)
    return len(pairs)
