"""A reader's loader function from its ``"module:function"`` name, and the options it is called with.

Below both the registry (which picks a spec and runs its loader, in-process or in the reader child) and the reader
child (``volviz.io.isolated``, which runs the loader the registry names), so that neither imports the other for it
(issue #31: the registry <-> isolated import circle).
"""
from __future__ import annotations

import importlib
import inspect
from typing import Any, Callable


class ReaderOptionError(TypeError):
    """An option the reader does not take."""


def resolve(target: str) -> Callable[..., Any]:
    """The object named by ``"module:function"`` (the module imported now); ValueError for any other form."""
    module, _, attr = target.partition(":")
    if not module or not attr:
        raise ValueError(f"reader target {target!r} is not 'module:function'")
    return getattr(importlib.import_module(module), attr)


def loader_call(kind: str, loader: str, options: dict) -> tuple[Callable[..., Any], dict]:
    """The loader function named ``loader`` and the options to call it with: ``allow_nonfinite`` is dropped for
    readers of integer-only formats, any other option it does not take is a ReaderOptionError naming it."""
    f = resolve(loader)
    params = inspect.signature(f).parameters
    accepts_kwargs = any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values())
    opts = dict(options)
    if "allow_nonfinite" in opts and "allow_nonfinite" not in params and not accepts_kwargs:
        opts.pop("allow_nonfinite")
    unknown = [k for k in opts if k not in params and not accepts_kwargs]
    if unknown:
        taken = [name for name in list(params)[1:] if params[name].kind is not inspect.Parameter.VAR_KEYWORD]
        raise ReaderOptionError(f"the {kind} reader does not take option(s) {', '.join(unknown)}; it takes "
                                f"{', '.join(taken) or 'none'}")
    return f, opts
