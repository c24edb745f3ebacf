"""The types of the session file's free-form JSON (issue #31, typed seams): a value as ``json.load`` gives it, and an
object of such values (a component's settings, render and dataset options, clipping), so that signatures say what
they take instead of ``Any``; code that reads a typed value out of one checks it with ``isinstance`` first."""
from __future__ import annotations

from typing import SupportsFloat, SupportsIndex, SupportsInt, Union

__all__ = ["JSONObject", "JSONValue", "json_float", "json_int"]

#: a JSON value: null, a boolean, a number, a string, an array or an object of JSON values (recursive; mypy follows)
JSONValue = Union[None, bool, int, float, str, list["JSONValue"], dict[str, "JSONValue"]]
#: a JSON object
JSONObject = dict[str, JSONValue]


def json_float(value: object) -> float:
    """``float(value)`` for what ``float`` takes (a number, a numeric string), narrowed for the type checker; anything
    else raises the TypeError ``float`` raises. For a number read out of a free-form option."""
    if isinstance(value, (str, bytes, bytearray, SupportsFloat, SupportsIndex)):
        return float(value)
    raise TypeError(f"float() argument must be a string or a real number, not {type(value).__name__!r}")


def json_int(value: object) -> int:
    """``int(value)`` for what ``int`` takes (a number, a numeric string), narrowed for the type checker; anything
    else raises the TypeError ``int`` raises. For a count read out of a free-form option."""
    if isinstance(value, (str, bytes, bytearray, SupportsInt, SupportsIndex)):
        return int(value)
    raise TypeError(f"int() argument must be a string, a bytes-like object or a real number, not "
                    f"{type(value).__name__!r}")
