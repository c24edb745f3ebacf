"""Reader options checked against the reader's signature before the reader runs (issue #32).

Options come from session files and the command line as plain JSON data. A reader called with an option it does not
take, without one it needs, or with a value of another type fails deep inside with a ``TypeError`` that names no
option; :func:`check_reader_options` finds the reader that will read ``path`` (as ``volviz.io.read`` does) and checks
the options against its parameters and their annotations first, naming the option and both values."""
from __future__ import annotations

import collections.abc
import inspect
import os
import types
import typing
from typing import Any, Literal, Union

from volviz.io.errors import PathLike, ReadError
from volviz.io.loaders import ReaderOptionError, loader_call
from volviz.io.registry import is_pattern, spec_of

__all__ = ["OptionProblem", "check_reader_options", "fits"]


class OptionProblem(ValueError):
    """An option that the reader of a file would not accept: ``option`` (None: the set of options) and ``problem``."""

    def __init__(self, option: str | None, problem: str) -> None:
        self.option = option
        self.problem = problem
        super().__init__(f"{option}: {problem}" if option else problem)


_SEQUENCES = (list, tuple, collections.abc.Sequence, collections.abc.Iterable, collections.abc.Collection)


def fits(value: Any, hint: Any) -> bool:
    """Whether the JSON value ``value`` fits the annotation ``hint``; annotations this does not understand (type
    variables, callables, protocols of arrays) accept anything but plain scalars and lists never match a class."""
    if hint is Any or hint is inspect.Parameter.empty or isinstance(hint, (typing.TypeVar, str)):
        return True
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin is Union or origin is types.UnionType:
        return any(fits(value, a) for a in args)
    if origin is Literal:
        return value in args
    if hint is type(None) or hint is None:
        return value is None
    if hint is bool:
        return isinstance(value, bool)
    if hint is int:
        return isinstance(value, int) and not isinstance(value, bool)
    if hint is float:
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if hint is str:
        return isinstance(value, str)
    if hint is os.PathLike or origin is os.PathLike:
        return isinstance(value, str)
    base = origin if origin is not None else hint
    if base in _SEQUENCES:
        if not isinstance(value, list):
            return False
        if base is tuple and args and args[-1] is not Ellipsis:
            return len(value) == len(args) and all(fits(v, a) for v, a in zip(value, args))
        item = args[0] if args else Any
        return all(fits(v, item) for v in value)
    if isinstance(base, type):
        try:
            return isinstance(value, base)
        except TypeError:  # a protocol that cannot be checked at run time: a JSON value is none of those
            return False
    return True


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


_WORDS: dict[Any, str] = {Any: "a value", bool: "true or false", int: "an integer", float: "a number",
                          str: "a string", type(None): "null"}


def _expected(hint: Any) -> str:
    """``hint`` in words, as a session author writes values: "a list of 3 integers or null"."""
    origin, args = typing.get_origin(hint), typing.get_args(hint)
    if origin is Union or origin is types.UnionType:
        words = list(dict.fromkeys(_expected(a) for a in args))
        plain = [w for w in words if w.startswith(("a ", "an ", "true", "null", "one of"))]
        words = plain or words  # what a JSON value can be (DTypeLike: a string, not the numpy protocols)
        return " or ".join(words) if len(words) <= 4 else ", ".join(words[:4]) + " or ..."
    if origin is Literal:
        return "one of " + ", ".join(repr(a) for a in args)
    if hint in _WORDS:
        return _WORDS[hint]
    base = origin if origin is not None else hint
    if base in _SEQUENCES:
        if base is tuple and args and args[-1] is not Ellipsis:
            kinds = list(dict.fromkeys(_expected(a) for a in args))
            return f"a list of {len(args)} " + (kinds[0].split(" ", 1)[-1] + "s" if len(kinds) == 1 else "values")
        return f"a list of {_expected(args[0]).split(' ', 1)[-1]}s" if args else "a list"
    return getattr(base, "__name__", str(base))


def check_reader_options(path: PathLike, options: dict[str, Any]) -> None:
    """Check ``options`` against the reader that would read ``path``: every option one it takes, every parameter it
    needs given, every value of the annotated type. Raises :class:`OptionProblem`; a path whose reader cannot be
    found (missing, unknown format, a series pattern, a ``.vvz``) is left to the read, which reports it."""
    if is_pattern(path) or os.fspath(path).lower().endswith(".vvz"):
        return
    try:
        spec = spec_of(path, options)
        f, opts = loader_call(spec.name, spec.loader, options)
    except ReaderOptionError as exc:
        taken = inspect.signature(spec.load_function()).parameters
        unknown = [k for k in options if k not in taken and k != "allow_nonfinite"]
        raise OptionProblem(unknown[0] if len(unknown) == 1 else None, str(exc)) from None
    except (ReadError, OSError, ValueError, ImportError):
        return
    params = list(inspect.signature(f).parameters.values())[1:]
    missing = [p.name for p in params if p.default is inspect.Parameter.empty and p.name not in opts
               and p.kind in (inspect.Parameter.POSITIONAL_OR_KEYWORD, inspect.Parameter.KEYWORD_ONLY)]
    if missing:
        raise OptionProblem(None, f"the {spec.name} reader needs option(s) {', '.join(missing)}")
    hints = _hints(f)
    for name, value in opts.items():
        hint = hints.get(name, Any)
        if not fits(value, hint):
            raise OptionProblem(name, f"is {_shown(value)}; the {spec.name} reader takes {_expected(hint)}")


def _hints(f: Any) -> dict[str, Any]:
    """The evaluated annotations of ``f``'s parameters (``os`` known to forward references such as
    ``volviz.io.errors.PathLike``); one that does not evaluate is left out: the reader checks that option itself."""
    try:
        return typing.get_type_hints(f, localns={"os": os})
    except Exception:  # noqa: BLE001 - annotations of any form; evaluate them one by one below
        pass
    hints: dict[str, Any] = {}
    for name, ann in getattr(f, "__annotations__", {}).items():
        try:
            hints[name] = eval(ann, getattr(f, "__globals__", {}), {"os": os}) if isinstance(ann, str) else ann
        except Exception:  # noqa: BLE001
            continue
    return hints
