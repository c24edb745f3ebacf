"""Crash-isolated reading: loaders that run native code (VTK's C++ readers, HDF5, netCDF) run in a child process.

A malformed file can make a C++ reader dereference a wild pointer, abort, allocate without bound or loop forever;
in-process, any of these takes the whole application (and everything the user had open) with it. Reader specs marked
``isolated=True`` in the registry are therefore run by ``volviz.io.read`` in a child process (``python -m
volviz.io.isolated``) under

- a memory limit (RLIMIT_AS on top of what the child already maps): ``max(2 GiB, 8 x data size)``, at most the
  memory available now; ``VOLVIZ_READ_MEMORY`` (``4G``, ``512M``, bytes) sets it instead;
- a time limit: ``60 s + 0.5 s per MB`` of data; ``VOLVIZ_READ_SECONDS`` sets it instead.

The child answers with a JSON description of the dataset (``codec``); its arrays come back as ``.npy`` files in a
private folder on ``/dev/shm`` (memory, where there is room) or the temporary folder, read (large ones mapped
copy-on-write, not copied) with ``allow_pickle=False`` and checked against that description. A crash, abort,
out-of-memory or time-out becomes a ``ReadError`` naming the file and what happened, and the calling process goes
on. Children are kept warm between reads (``prewarm()`` starts one ahead of the first read). A time series' lazy
frames are read the same way.

``VOLVIZ_ISOLATE=0`` (or ``volviz.io.read(path, isolate=False)``) reads in-process, to debug a reader.
"""
from __future__ import annotations

import math
import os
import re
import shutil
import sys
import tempfile
import threading
import warnings
from dataclasses import dataclass
from typing import Any

import numpy as np

from volviz.io.errors import ChoiceWarning, NonFiniteWarning, PathLike, ReadError, ReadWarning, human_bytes
from volviz.io.isolated.codec import CodecError, array_specs, decode
from volviz.io.isolated.worker import ChildDied, ChildTimedOut, Pool
from volviz.io.loaders import ReaderOptionError

GIB = 1 << 30
WORKDIR_PREFIX = "volviz-read-"
MAP_BYTES = 1 << 20  # arrays from this size on are mapped, smaller ones copied (each mapping costs a page and a slot)
_FALSE = ("0", "false", "no", "off")
_SIZE = re.compile(r"\s*(\d+(?:\.\d+)?)\s*([kmgt]?)i?b?\s*", re.I)
_WARNINGS = {c.__name__: c for c in (NonFiniteWarning, ReadWarning, ChoiceWarning, UserWarning, RuntimeWarning,
                                     DeprecationWarning, FutureWarning, ResourceWarning)}


def isolation_enabled(isolate: bool | None = None) -> bool:
    """``isolate`` if given, else whether ``VOLVIZ_ISOLATE`` is unset or not ``0``/``false``/``no``/``off``."""
    if isolate is not None:
        return bool(isolate)
    return os.environ.get("VOLVIZ_ISOLATE", "1").strip().lower() not in _FALSE


def parse_size(text: str) -> int:
    """``"4G"`` -> 4 GiB, ``"512M"``, ``"1.5g"``, plain bytes; ValueError otherwise."""
    m = _SIZE.fullmatch(text)
    if m is None:
        raise ValueError(f"{text!r} is not a size such as 4G, 512M or a number of bytes")
    return int(float(m.group(1)) * 1024 ** "_kmgt".index(m.group(2).lower() or "_"))


def proc_bytes(file: str, key: str) -> int | None:
    """A ``key: N kB`` line of a /proc file (``/proc/meminfo``, ``/proc/self/status``) in bytes; None if absent."""
    try:
        with open(file) as fh:
            for line in fh:
                if line.startswith(key + ":"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def available_memory() -> int:
    """MemAvailable (bytes); a large number where it cannot be read."""
    found = proc_bytes("/proc/meminfo", "MemAvailable")
    return (1 << 62) if found is None else found


@dataclass
class Limits:
    """What one isolated read may use; ``VOLVIZ_READ_MEMORY`` / ``VOLVIZ_READ_SECONDS`` override the formulas."""

    memory_floor: int = 2 * GIB
    memory_per_byte: float = 8.0
    min_memory: int = 512 << 20
    seconds_base: float = 60.0
    seconds_per_mb: float = 0.5

    def memory(self, data_bytes: int) -> int:
        """The address-space budget of a read of ``data_bytes``: ``max(floor, 8 x size)``, capped by the memory
        available now (never below ``min_memory``)."""
        fixed = os.environ.get("VOLVIZ_READ_MEMORY", "").strip()
        if fixed:
            return parse_size(fixed)
        wanted = max(self.memory_floor, int(self.memory_per_byte * data_bytes))
        return max(self.min_memory, min(wanted, available_memory()))

    def seconds(self, data_bytes: int) -> float:
        fixed = os.environ.get("VOLVIZ_READ_SECONDS", "").strip()
        if fixed:
            return float(fixed)
        return self.seconds_base + self.seconds_per_mb * data_bytes / 1e6


limits = Limits()
_pool = Pool()


def prewarm(idle_load: bool = True) -> None:
    """Start a reader child in the background so that the first isolated read does not wait for its start-up;
    ``idle_load=False`` for a child started for one read at hand (``worker.Worker``)."""
    _pool.prewarm(idle_load)


def shutdown() -> None:
    """End the idle reader children (they also end with this process)."""
    _pool.shutdown()


def data_size(path: PathLike) -> int:
    """Bytes a read of ``path`` is likely to touch: the file, or for a folder or a small descriptor file (``.foam``,
    ``.case``, ``.vtm``, ``.pvtu``) the files beside it (at most 2000 looked at)."""
    p = os.fspath(path)
    try:
        if os.path.isfile(p) and os.path.getsize(p) >= 1 << 16:
            return os.path.getsize(p)
        folder = p if os.path.isdir(p) else os.path.dirname(os.path.abspath(p))
    except OSError:
        return 0
    total, seen = 0, 0
    for root, _dirs, files in os.walk(folder):
        for name in files:
            seen += 1
            try:
                total += os.path.getsize(os.path.join(root, name))
            except OSError:
                pass
            if seen >= 2000:
                return total
    return total


def engine(spec: Any) -> str:
    """Whose code the spec's loader runs, for messages: "VTK's reader", "meshio's reader" or "the reader"."""
    if spec.loader.startswith(("volviz.io.vtk", "volviz_vtk_readers")):
        return "VTK's reader"
    if "meshio" in spec.loader:
        return "meshio's reader"
    return "the reader"


# -- the exchange folder -----------------------------------------------------------------------------------------------
_cleaned = threading.Event()


def _exchange_base(data_bytes: int) -> str:
    """/dev/shm when it has room for a few times the data, else the temporary folder."""
    shm = "/dev/shm"
    try:
        st = os.statvfs(shm)
        if os.access(shm, os.W_OK) and st.f_bavail * st.f_frsize > 4 * data_bytes + (256 << 20):
            return shm
    except OSError:
        pass
    return tempfile.gettempdir()


def _remove_stale(base: str) -> None:
    """Exchange folders left by processes that were killed mid-read (their pid is in the name)."""
    try:
        names = os.listdir(base)
    except OSError:
        return
    for name in names:
        m = re.fullmatch(re.escape(WORKDIR_PREFIX) + r"(\d+)-.*", name)
        if m is None or int(m.group(1)) == os.getpid():
            continue
        try:
            os.kill(int(m.group(1)), 0)
        except ProcessLookupError:
            shutil.rmtree(os.path.join(base, name), ignore_errors=True)
        except OSError:
            pass


def _workdir(data_bytes: int) -> str:
    base = _exchange_base(data_bytes)
    if not _cleaned.is_set():
        _cleaned.set()
        _remove_stale(base)
    return tempfile.mkdtemp(prefix=f"{WORKDIR_PREFIX}{os.getpid()}-", dir=base)


# -- one read ----------------------------------------------------------------------------------------------------------
def _plain(value: Any, name: str) -> Any:
    """An option value as JSON (paths as strings, tuples as lists); TypeError for anything else."""
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    if isinstance(value, (list, tuple)):
        return [_plain(v, name) for v in value]
    if isinstance(value, dict) and all(isinstance(k, str) for k in value):
        return {k: _plain(v, name) for k, v in value.items()}
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"option {name}={value!r} cannot be passed to an isolated reader (plain values only)")


def _load_array(path: str, nbytes: int) -> np.ndarray:
    """A .npy file the child wrote (no pickles). A large one is mapped copy-on-write rather than copied: its pages
    stay where the child wrote them (memory, on /dev/shm) and outlive the file's removal."""
    if nbytes >= MAP_BYTES and os.name == "posix":
        return np.asarray(np.load(path, mmap_mode="c", allow_pickle=False))
    return np.load(path, allow_pickle=False)


def _reemit(caught: Any) -> None:
    """The child's warnings again in this process: [category, message], a ``ChoiceWarning`` with its choices."""
    for item in caught if isinstance(caught, list) else []:
        if not (isinstance(item, list) and len(item) in (2, 3) and all(isinstance(t, str) for t in item[:2])):
            continue
        choice = ChoiceWarning.from_fields(item[1], item[2]) if len(item) == 3 and item[0] == "ChoiceWarning" else None
        if choice is not None:
            warnings.warn(choice, stacklevel=4)
        else:
            warnings.warn(item[1], _WARNINGS.get(item[0], UserWarning), stacklevel=4)


MAX_NAMES = 100_000     # names a ``names_isolated`` call may return
MAX_NAME_CHARS = 4096


class _Read:
    """One isolated call of a spec's loader on one path (with ``frame`` for a lazy frame of a time series); with
    ``loader`` and ``result="names"`` the call of another function of the reader that returns a list of names."""

    def __init__(self, spec: Any, path: PathLike, options: dict, limits_: Limits, loader: str | None = None,
                 result: str = "dataset") -> None:
        self.spec, self.limits = spec, limits_
        self.loader, self.result = loader or spec.loader, result
        self.shown = os.fspath(path)
        self.path = os.path.abspath(self.shown)
        self.options = {k: _plain(v, k) for k, v in options.items()}
        self.size = data_size(self.path)

    def fail(self, problem: str) -> ReadError:
        return ReadError(self.shown, problem)

    def __call__(self, frame: int | None = None) -> Any:
        memory, seconds = self.limits.memory(self.size), self.limits.seconds(self.size)
        workdir = _workdir(self.size)
        request = {"path": self.path, "kind": self.spec.name, "loader": self.loader, "options": self.options,
                   "frame": frame, "result": self.result, "memory": memory, "workdir": workdir,
                   "sys_path": [p for p in sys.path if isinstance(p, str)]}
        try:
            answer = self._ask(request, seconds)
            return self._result(answer, workdir, memory)
        except ChildTimedOut:
            raise self.fail(f"{engine(self.spec)} did not finish within the time limit of {seconds:.0f} s and was "
                            f"stopped: the file is damaged (a count that makes the reader loop) or too large for "
                            f"the limit (VOLVIZ_READ_SECONDS)") from None
        except ChildDied as exc:
            raise self.fail(self._death(exc, memory)) from None
        finally:
            shutil.rmtree(workdir, ignore_errors=True)

    @staticmethod
    def _ask(request: dict, seconds: float) -> Any:
        worker = _pool.take()
        try:
            answer = worker.request(request, seconds)
        except (ChildTimedOut, ChildDied):
            worker.kill()    # gone or stopped: its pipes are closed now
            _pool.prewarm()  # the next read finds a child started, not a cold start
            raise
        except BaseException:
            worker.kill()  # interrupted while the child works: it cannot be reused
            raise
        _pool.give(worker)
        return answer

    def _death(self, exc: ChildDied, memory: int) -> str:
        what = exc.what
        if "bad_alloc" in exc.tail or "Killed" in what or "SIGKILL" in what:
            return (f"{engine(self.spec)} ran out of memory reading it (limit {human_bytes(memory)}, "
                    f"VOLVIZ_READ_MEMORY): the file is damaged (a size that does not fit it) or needs more memory")
        what = f"crashed ({what})" if what == "aborted" else what
        return (f"{engine(self.spec)} {what} reading it: the file is damaged or not a valid "
                f"{self.spec.description} file")

    def _result(self, answer: Any, workdir: str, memory: int) -> Any:
        if not isinstance(answer, dict):
            raise self.fail(f"{engine(self.spec)} process answered something that is not a result")
        _reemit(answer.get("warnings"))
        if not answer.get("ok"):
            raise self._error(answer, memory)
        if self.result == "names":
            names = answer.get("names")
            if not (isinstance(names, list) and len(names) <= MAX_NAMES
                    and all(isinstance(n, str) and len(n) <= MAX_NAME_CHARS for n in names)):
                raise self.fail("the isolated reader's answer is not a list of names")
            return names
        header: Any = answer.get("header")  # the child's JSON, checked by array_specs and decode
        try:
            specs = array_specs(header)
            arrays = [_load_array(os.path.join(workdir, f"a{i}.npy"), dtype.itemsize * math.prod(shape))
                      for i, (dtype, shape) in enumerate(specs)]
            dataset = decode(header, arrays)
        except (CodecError, OSError, ValueError, TypeError, IndexError) as exc:
            raise self.fail(f"the isolated reader's result is not a valid dataset ({exc})") from None
        if getattr(dataset, "kind", "") == "time series" and header["dataset"]["lazy"]:
            dataset.loader = _FrameLoader(self)
        return dataset

    def _error(self, answer: dict, memory: int) -> Exception:
        kind = answer.get("error")
        if kind == "read":
            path, problem = str(answer.get("path", "")), str(answer.get("problem", ""))
            advice = answer.get("advice") if isinstance(answer.get("advice"), str) else None
            return ReadError(self.shown if path in (self.path, "") else path, problem, advice)
        if kind == "options":
            return ReaderOptionError(str(answer.get("message")))
        if kind == "memory":
            return self.fail(f"{engine(self.spec)} needs more memory than the limit of {human_bytes(memory)} "
                             f"(VOLVIZ_READ_MEMORY): the file is damaged (a size that does not fit it) or too large")
        if kind == "refused":
            return self.fail(f"the {self.spec.name} reader's result is refused: {answer.get('message')}")
        return self.fail(f"{engine(self.spec)} failed: {answer.get('type', 'error')}: {answer.get('message', '')}")


class _FrameLoader:
    """The loader of an isolated time series' lazy frames: each frame is one more isolated read."""

    def __init__(self, read: _Read) -> None:
        self.read = read

    def __call__(self, index: int) -> Any:
        frame = self.read(index)
        if getattr(frame, "kind", "") == "time series":
            raise self.read.fail(f"frame {index} is itself a time series")
        return frame


def read_isolated(spec: Any, path: PathLike, options: dict, limits_: Limits | None = None) -> Any:
    """Run ``spec``'s loader on ``path`` with ``options`` in a reader child (see the module docstring)."""
    return _Read(spec, path, options, limits_ or limits)()


def names_isolated(spec: Any, path: PathLike, function: str, limits_: Limits | None = None) -> list[str]:
    """Run ``function`` (``"module:name"``, taking the path, returning a list of strings: the block names of a
    file) in a reader child under ``spec``'s limits; the names come back as JSON, checked to be strings."""
    return _Read(spec, path, {}, limits_ or limits, loader=function, result="names")()
