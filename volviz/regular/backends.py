"""Compression backends: where the independent parts of a series encoding run (``compress_series(scheduler=)``).

A backend is found by name in the entry-point group ``volviz.compression_backends``. Its entry point names a function
``run(address, func, tasks)`` that calls ``func(*task)`` for every argument tuple of the iterable ``tasks`` on the
cluster at ``address`` and yields the results, in any order. volviz's own Dask backend is the plugin
``plugins/volviz-dask``.
"""
from __future__ import annotations

from importlib.metadata import entry_points
from typing import Any, Callable, Iterable, Iterator

ENTRY_POINT_GROUP = "volviz.compression_backends"
Backend = Callable[[str, Callable[..., Any], Iterable[tuple]], Iterator[Any]]
# the distribution that provides each backend volviz knows of, for the "install it" message
KNOWN_BACKENDS = {"dask": "volviz-dask (pip install -e plugins/volviz-dask, or pip install 'volviz[cluster]' with the "
                          "plugin)"}


class BackendMissing(RuntimeError):
    """No installed package registers the compression backend asked for."""


def backend_names() -> list[str]:
    return sorted({ep.name for ep in entry_points(group=ENTRY_POINT_GROUP)})


def compression_backend(name: str) -> Backend:
    """The ``run`` function of the backend registered as ``name``; BackendMissing says which package to install."""
    found = [ep for ep in entry_points(group=ENTRY_POINT_GROUP) if ep.name == name]
    if not found:
        hint = KNOWN_BACKENDS.get(name, f"a package registering {name!r} in the entry-point group {ENTRY_POINT_GROUP}")
        installed = ", ".join(backend_names()) or "none"
        raise BackendMissing(f"the {name!r} compression backend is not installed (installed: {installed}); install "
                             f"{hint}")
    return found[0].load()
