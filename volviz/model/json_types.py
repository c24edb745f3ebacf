"""The types of the session file's free-form JSON (issue #31, typed seams): a value as ``json.load`` gives it, and an
object of such values (a component's settings, render and dataset options, clipping), so that signatures say what
they take instead of ``Any``; code that reads a typed value out of one checks it with ``isinstance`` first."""
from __future__ import annotations

from typing import Union

__all__ = ["JSONObject", "JSONValue"]

#: a JSON value: null, a boolean, a number, a string, an array or an object of JSON values (recursive; mypy follows)
JSONValue = Union[None, bool, int, float, str, list["JSONValue"], dict[str, "JSONValue"]]
#: a JSON object
JSONObject = dict[str, JSONValue]
