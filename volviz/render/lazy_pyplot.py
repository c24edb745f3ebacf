"""matplotlib's pyplot and Agg backend run on first use: pyvista 0.49 imports ``matplotlib.pyplot`` in
``pyvista.plotting.colors`` and ``.charts`` for one rcParams lookup (its default color cycler) and its matplotlib
charts, and ``matplotlib.backends.backend_agg`` in ``.charts`` for the canvas of ``ChartMPL``, which a render never
makes; pyplot's body (the figure manager, the backend's resolution) and the backend's (``matplotlib.backend_bases``:
text, fonts, mathtext, patches, widgets) cost up to a second of a fresh process's start under load (issue #30;
docs/bench/startup.md, docs/bench/startup-cuts.md, docs/bench/docstring-figures.md).

``defer_pyplot`` puts a finder first on ``sys.meta_path`` that gives each of ``DEFERRED`` a module whose body runs
at the first lookup of a name it does not hold yet (a module-level ``__getattr__``): ``import matplotlib.pyplot``
binds it for nothing, any use of ``plt.NAME`` gets the real module (the same object, its body run in place), so
code that uses pyplot sees no difference. A ``from`` import is such a lookup, so the one of ``STAND_INS`` gets a
stand-in instead, which runs the body at its first call and calls the real object: only the importer named there
(pyvista's charts, which only call the canvas class); any other importer gets the real object. The standard
library's ``importlib.util.LazyLoader`` does not serve: in Python 3.11 a second ``import matplotlib.pyplot`` reads
the module's ``__spec__``, which runs the body. pyvista's files are not changed.
"""
from __future__ import annotations

import importlib.abc
import importlib.machinery
import sys
import threading
from types import ModuleType
from typing import Any, Optional, Sequence

__all__ = ["DEFERRED", "PYPLOT", "STAND_INS", "defer_pyplot", "pyplot_ran", "ran"]

PYPLOT = "matplotlib.pyplot"
AGG = "matplotlib.backends.backend_agg"
#: the modules whose body runs at its first use
DEFERRED = (PYPLOT, AGG)
#: (module, name) -> the one importer whose ``from module import name`` gets a stand-in (``_StandIn``)
STAND_INS = {(AGG, "FigureCanvasAgg"): "pyvista.plotting.charts"}
_LOCK = threading.RLock()
_RUNNING: set[str] = set()   # modules whose body runs now


class _Deferred(ModuleType):
    """A module whose body has not run: the first lookup of a name it lacks runs it (``_run``); the import system's
    own lookups of dunder attributes (``__file__``, ``__path__``, ...) do not, but ``__all__`` (a star import) and
    ``dir()`` do."""

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__") and name.endswith("__") and name != "__all__":
            raise AttributeError(name)
        importer = STAND_INS.get((self.__name__, name))
        if importer is not None and sys._getframe(1).f_globals.get("__name__") == importer:
            return _StandIn(self, name)
        _run(self)
        if type(self) is _Deferred:         # its body is running in this thread and lacks the name so far
            raise AttributeError(f"partially initialized module {self.__name__!r} has no attribute {name!r}")
        return getattr(self, name)

    def __dir__(self) -> list[str]:
        _run(self)
        return list(self.__dict__)


def _run(module: ModuleType) -> None:
    """Run the real loader's body in ``module``, once, under a lock (another thread's first use waits for it); the
    module is plain from then on. A failed body leaves the module out of ``sys.modules``, as a failed import does."""
    with _LOCK:
        if type(module) is not _Deferred or module.__name__ in _RUNNING:
            return
        _RUNNING.add(module.__name__)
        try:
            loader = module.__spec__.loader_state    # type: ignore[union-attr]
            module.__loader__ = loader
            module.__spec__.loader = loader          # type: ignore[union-attr]
            loader.exec_module(module)
        except BaseException:
            sys.modules.pop(module.__name__, None)
            raise
        finally:
            _RUNNING.discard(module.__name__)
        setattr(module, "__class__", ModuleType)   # a plain module from now on (no more __getattr__)


class _StandIn:
    """A name of a deferred module, handed to the importer ``STAND_INS`` names: its first call runs the module's
    body (``_run``); every call calls the real object."""

    def __init__(self, module: ModuleType, name: str) -> None:
        self._module = module
        self._name = name

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        _run(self._module)
        return getattr(self._module, self._name)(*args, **kwargs)


class _DeferredLoader(importlib.abc.Loader):
    """Creates a ``_Deferred`` module and leaves its body to its first use."""

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        return _Deferred(spec.name)

    def exec_module(self, module: ModuleType) -> None:
        return None


class _PyplotFinder(importlib.abc.MetaPathFinder):
    """Finds each of ``DEFERRED`` as the finders after it do; its loader kept in the spec's ``loader_state``."""

    def find_spec(self, fullname: str, path: Optional[Sequence[str]],
                  target: Optional[ModuleType] = None) -> Optional[importlib.machinery.ModuleSpec]:
        if fullname not in DEFERRED:
            return None
        for finder in sys.meta_path:
            if finder is self or not hasattr(finder, "find_spec"):
                continue
            spec = finder.find_spec(fullname, path, target)
            if spec is None:
                continue
            if spec.loader is None or not hasattr(spec.loader, "exec_module") or spec.loader_state is not None:
                return spec
            spec.loader_state, spec.loader = spec.loader, _DeferredLoader()
            return spec
        return None


def defer_pyplot() -> None:
    """From now on in this process, each of ``DEFERRED`` not imported yet runs at its first use, not at its import
    (nothing when the finder is in place)."""
    if any(isinstance(f, _PyplotFinder) for f in sys.meta_path):
        return
    sys.meta_path.insert(0, _PyplotFinder())


def ran(name: str) -> bool:
    """Whether the body of the module ``name`` has run in this process."""
    module = sys.modules.get(name)
    return module is not None and type(module) is not _Deferred


def pyplot_ran() -> bool:
    """Whether pyplot's body has run in this process."""
    return ran(PYPLOT)
