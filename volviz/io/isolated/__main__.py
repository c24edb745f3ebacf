"""The reader child: ``python -m volviz.io.isolated`` (started by ``volviz.io.isolated``, not by hand).

It reads one JSON request per line on stdin -- ``{"path", "kind", "loader", "options", "frame", "memory", "workdir",
"sys_path"}`` -- runs the loader under a memory limit (RLIMIT_AS: the address space it has now plus the request's
budget), writes the arrays of the result as ``a0.npy, a1.npy, ...`` into ``workdir`` and answers one JSON line on
stdout: ``{"ok": true, "header": ..., "warnings": [...]}`` or ``{"ok": false, "error": ..., ...}``. It leaves at the
end of its stdin, and with its parent (Linux: PR_SET_PDEATHSIG).
"""
from __future__ import annotations

import importlib
import json
import os
import resource
import select
import sys
import threading
import time
import warnings
from collections import OrderedDict
from typing import Any, BinaryIO

import numpy as np

from volviz.io.errors import ChoiceWarning, ReadError
from volviz.io.isolated import proc_bytes
from volviz.io.isolated.codec import CodecError, encode
from volviz.io.loaders import ReaderOptionError, loader_call
from volviz.io.vtk_lazy import MODULE_OF

SERIES_CACHE = 2  # transient files kept open for their lazy frames


def _protocol_stdout() -> BinaryIO:
    """Our own copy of stdout for the answers; fd 1 then points at stderr, so prints cannot break the protocol."""
    out = os.fdopen(os.dup(1), "wb", buffering=0)
    os.dup2(2, 1)
    sys.stdout = sys.stderr
    return out


def _die_with_parent() -> None:
    """Leave when the parent process is gone, even in the middle of a read: a watchdog thread compares the parent's
    id every half second (PR_SET_PDEATHSIG would fire when the parent *thread* that started this child ends, and
    the app starts readers from short-lived worker threads). Between reads the child also leaves at the end of its
    stdin."""
    parent = os.getppid()

    def watch() -> None:
        while os.getppid() == parent:
            time.sleep(0.5)
        os._exit(0)

    threading.Thread(target=watch, name="volviz-reader-watchdog", daemon=True).start()



def _warning(message: Warning | str) -> list:
    """A caught warning for the parent: [category, message], and a ``ChoiceWarning``'s choices as a third item."""
    item: list = [type(message).__name__ if isinstance(message, Warning) else "UserWarning", str(message)[:2000]]
    if isinstance(message, ChoiceWarning):
        item.append(message.fields())
    return item

class _MemoryLimit:
    """RLIMIT_AS lowered to the present address space plus ``budget`` for the duration of one read."""

    def __init__(self, budget: int) -> None:
        self.budget = budget

    def __enter__(self) -> None:
        self._old = resource.getrlimit(resource.RLIMIT_AS)
        if self.budget > 0:
            hard = self._old[1]
            soft = (proc_bytes("/proc/self/status", "VmSize") or 0) + self.budget
            resource.setrlimit(resource.RLIMIT_AS, (soft if hard == resource.RLIM_INFINITY else min(soft, hard), hard))

    def __exit__(self, *exc: Any) -> None:
        resource.setrlimit(resource.RLIMIT_AS, self._old)


def _names(value: Any) -> list[str]:
    """A loader's list of names, checked (the parent checks again)."""
    if not isinstance(value, (list, tuple)) or not all(isinstance(v, str) for v in value):
        raise CodecError(f"the function returned a {type(value).__name__}, not a list of names")
    return list(value)


class Child:
    def __init__(self) -> None:
        self.series: OrderedDict[str, Any] = OrderedDict()

    def _load(self, request: dict) -> Any:
        """The loader's dataset, or with ``frame`` one frame of the time series it returns. A lazy series stays open
        here (the last few, keyed by loader, path, options and the file's mtime and size) for its later frames,
        holding frame 0 only: a frame handed back is dropped again."""
        f, opts = loader_call(request["kind"], request["loader"], request["options"])
        frame = request.get("frame")
        try:
            st = os.stat(request["path"])
            stamp = [st.st_mtime_ns, st.st_size]
        except OSError:
            stamp = None
        key = json.dumps([request["loader"], request["path"], request["options"], stamp], sort_keys=True)
        series = self.series.pop(key, None) if frame is not None else None
        if series is None:
            series = f(request["path"], **opts)
        if getattr(series, "loader", None) is not None and hasattr(series, "frame"):
            self.series[key] = series
            while len(self.series) > SERIES_CACHE:
                self.series.popitem(last=False)
        if frame is None:
            return series
        if not hasattr(series, "frame"):
            raise TypeError(f"frame {frame} was asked of a {type(series).__name__}, not a time series")
        item = series.frame(frame)
        if frame != 0:
            series.frames[frame] = None
        return item

    def handle(self, request: dict) -> dict:
        for entry in request.get("sys_path", []):
            if isinstance(entry, str) and entry not in sys.path:
                sys.path.append(entry)
        arrays: list[np.ndarray] | None = None
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            try:
                with _MemoryLimit(int(request.get("memory", 0))):
                    dataset = self._load(request)
                    if request.get("result") == "names":
                        answer: dict = {"ok": True, "names": _names(dataset)}
                    else:
                        header, arrays = encode(dataset)
                        for i, arr in enumerate(arrays):
                            np.save(os.path.join(request["workdir"], f"a{i}.npy"), arr, allow_pickle=False)
                        answer = {"ok": True, "header": header}
            except ReadError as exc:
                answer = {"ok": False, "error": "read", "path": exc.path, "problem": exc.problem,
                          "advice": exc.advice}
            except CodecError as exc:
                answer = {"ok": False, "error": "refused", "message": str(exc)}
            except ReaderOptionError as exc:
                answer = {"ok": False, "error": "options", "message": str(exc)}
            except MemoryError:
                answer = {"ok": False, "error": "memory"}
            except Exception as exc:  # reported to the parent, which names the file
                answer = {"ok": False, "error": "exception", "type": type(exc).__name__, "message": str(exc)[:2000]}
            finally:
                dataset = arrays = None
        answer["warnings"] = [_warning(w.message) for w in caught[:50]]
        return answer


#: how long a child that was just started waits for a request before it loads all of VTK while idle
IDLE_SECONDS = 0.25


def _load_vtk_when_idle() -> None:
    """Import the VTK modules of volviz's readers (``volviz.io.vtk_lazy.MODULE_OF``, by name: not the whole of VTK,
    issue #31) until a request is waiting. A child kept warm for later reads (the app's pool) has them
    loaded before they come; one started for a read at hand (``volviz render FILE``, with ``worker.AT_HAND``) does
    not run this: its reader imports only the VTK modules it uses (``volviz.io.vtk_lazy``, a fraction of the whole).
    """
    if select.select([sys.stdin.buffer], [], [], IDLE_SECONDS)[0]:
        return
    for module in sorted(set(MODULE_OF.values())):
        if select.select([sys.stdin.buffer], [], [], 0)[0]:   # a request came meanwhile (a child started ahead of
            return                                            # its read, ``volviz render``): it is not kept waiting
        try:
            importlib.import_module(f"vtkmodules.{module}")
        except ImportError:  # a module this VTK build lacks: its readers report that themselves
            pass


def main() -> None:
    out = _protocol_stdout()
    _die_with_parent()
    from volviz.io.isolated.worker import AT_HAND   # loaded with the package above

    out.write(json.dumps({"ready": True, "pid": os.getpid()}).encode() + b"\n")
    if AT_HAND not in sys.argv[1:]:
        _load_vtk_when_idle()
    child = Child()
    for line in sys.stdin.buffer:
        try:
            request = json.loads(line)
        except ValueError:
            answer = {"ok": False, "error": "exception", "type": "ValueError", "message": "request is not JSON"}
        else:
            answer = child.handle(request)
        out.write(json.dumps(answer).encode() + b"\n")


if __name__ == "__main__":
    main()
