"""``volviz.render.gl_thread.GLThread``: its calls run on one thread of its own, and its window is released there
when it is closed or collected, wherever the collector runs.

The fresh-clone CI run on 3c929b3 hung for good in test_iso_modes_volume: a GLThread collected while
``ThreadPoolExecutor.submit`` (its pool's) held ``concurrent.futures.thread``'s global shutdown lock submitted its
window's close to its own executor, whose ``submit`` waits for that lock: the collector's thread waited on itself.
The second test holds that lock (as ``submit`` does) while a GLThread is collected."""
from __future__ import annotations

import gc
import threading
from concurrent.futures import thread as futures_thread

from volviz.render.gl_thread import GLThread


def _made(renderer) -> int:
    return threading.get_ident()


def test_calls_run_on_one_thread_of_their_own_and_close_releases_the_window() -> None:
    gl = GLThread()
    ran = {gl.call(_made) for _ in range(3)}
    assert ran == gl.threads and threading.get_ident() not in ran and gl.calls == 3
    assert "window" in gl.state
    gl.close()
    assert gl.state == {}                    # the window and the renderer went on the thread


def test_a_gl_thread_collected_while_an_executor_holds_its_global_lock_does_not_hang() -> None:
    holder = {"gl": GLThread()}
    holder["gl"].call(_made)                 # its window is made: collecting it has a window to close
    state = holder["gl"].state
    finished = threading.Event()

    def collect() -> None:
        with futures_thread._global_shutdown_lock:   # held by any ThreadPoolExecutor.submit in progress
            holder.clear()
            gc.collect()
        finished.set()

    worker = threading.Thread(target=collect, daemon=True)
    worker.start()
    worker.join(timeout=60)
    assert finished.is_set(), "collecting a GLThread hung"
    assert state == {}                       # its window was released on its thread


def test_close_without_waiting_leaves_the_call_in_progress_to_finish_and_refuses_later_calls() -> None:
    """A view removed on the GUI thread while its image is drawn on the GL thread (VTK's projected tetrahedra,
    ``volviz.render.vtk_pt_image``): ``close(wait=False)`` returns at once (waiting held the GUI thread for the rest of
    the image, 181 ms for the Blunt Fin at 1500x900), the call in progress finishes, the window is then released,
    and a call submitted after the close fails at once with ``GLThreadClosed`` instead of waiting for a thread that
    has ended."""
    import pytest

    from volviz.render.gl_thread import GLThreadClosed

    gl = GLThread()
    release = threading.Event()
    started = threading.Event()

    def long_call(renderer) -> int:
        started.set()
        release.wait(30)
        return 7

    in_progress = gl.submit(long_call)
    assert started.wait(30)
    gl.close(wait=False)
    assert not in_progress.done()            # close did not wait for it
    with pytest.raises(GLThreadClosed):
        gl.submit(_made).result(timeout=5)
    release.set()
    assert in_progress.result(timeout=30) == 7
    deadline = threading.Event()
    for _ in range(300):                     # the window is released on the thread after the call
        if gl.state == {}:
            break
        deadline.wait(0.1)
    assert gl.state == {}
