"""What VTK work a callable does from Python when run off the GUI thread, for the rule that background jobs make no
VTK objects (issue #28; ``volviz.jobs``: a worker making VTK objects while it holds the GIL can deadlock a render
on the GUI thread).

``on_worker(fn)`` runs ``fn`` on a new thread under a profile hook and returns its result with the VTK calls it
made: every call of a method of a VTK object or class (``c_call`` events whose ``__self__`` is a VTK object or
type) and every ``__init__`` of a Python subclass of a VTK class (PyVista's data sets and arrays), each named by
the VTK class, the method and the innermost volviz frame. Not seen: a bare VTK class called and never used (the
interpreter reports no event for calling a type), work in native code that calls VTK without Python."""
from __future__ import annotations

import sys
import threading
from typing import Any, Callable

from vtkmodules.vtkCommonCore import vtkObjectBase


def _where(frame: Any) -> str:
    """The innermost frame in volviz or the app, as ``path:line``."""
    while frame is not None:
        name = frame.f_code.co_filename.replace("\\", "/")
        if ("/volviz/" in name or "/app/" in name) and "site-packages" not in name:
            return f"{name.rsplit('/', 2)[-2]}/{name.rsplit('/', 1)[-1]}:{frame.f_lineno}"
        frame = frame.f_back
    return "?"


def _vtk_call(frame: Any, event: str, arg: Any) -> str | None:
    if event == "c_call":
        owner = getattr(arg, "__self__", None)
        kind = owner if isinstance(owner, type) else type(owner)
        if isinstance(kind, type) and issubclass(kind, vtkObjectBase):
            return f"{kind.__name__}.{getattr(arg, '__name__', '?')} at {_where(frame)}"
    elif event == "call" and frame.f_code.co_name == "__init__":
        if isinstance(frame.f_locals.get("self"), vtkObjectBase):
            return f"{type(frame.f_locals['self']).__name__}.__init__ at {_where(frame.f_back)}"
    return None


def on_worker(fn: Callable[[], Any]) -> tuple[Any, list[str]]:
    """``fn()`` run on a new thread (not the GUI thread): its result and the VTK calls it made there (first of
    each kind and place, in order). An exception in ``fn`` is raised here."""
    calls: dict[str, None] = {}
    out: dict[str, Any] = {}

    def hook(frame: Any, event: str, arg: Any) -> None:
        what = _vtk_call(frame, event, arg)
        if what is not None:
            calls.setdefault(what, None)

    def run() -> None:
        sys.setprofile(hook)
        try:
            out["result"] = fn()
        except BaseException as exc:  # handed to the caller
            out["error"] = exc
        finally:
            sys.setprofile(None)

    worker = threading.Thread(target=run, name="vtk-threads-probe")
    worker.start()
    worker.join()
    if "error" in out:
        raise out["error"]
    return out.get("result"), list(calls)


def vtk_objects_in(value: Any, depth: int = 4) -> list[str]:
    """The VTK objects ``value`` holds (itself, or inside dicts, lists, tuples and objects' attributes, ``depth``
    levels down), by class name: what a job would hand over to the GUI thread."""
    if isinstance(value, vtkObjectBase):
        return [type(value).__name__]
    if depth == 0 or value is None or isinstance(value, (str, bytes, int, float, bool)):
        return []
    if isinstance(value, dict):
        items = list(value.values())
    elif isinstance(value, (list, tuple, set, frozenset)):
        items = list(value)
    elif hasattr(value, "__dict__") and not isinstance(value, type):
        items = list(vars(value).values())
    else:
        return []
    return [name for item in items for name in vtk_objects_in(item, depth - 1)]
