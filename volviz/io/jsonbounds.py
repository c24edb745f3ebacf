"""Bounds of a JSON text checked on its bytes before ``json`` parses it (sessions, ``.vvz`` metadata).

``json.loads`` recurses once per nesting level: 100,000 nested brackets end in ``RecursionError``. These scans run
at C speed over the bytes between strings (no Python work per value), so a hostile text is measured, and refused
by the caller with its own message, before anything recurses or allocates per value."""
from __future__ import annotations

import re

import numpy as np

__all__ = ["outside_strings", "nesting_depth"]

_STRING = re.compile(rb'"[^"]*"')
_NOT_BRACKETS = bytes(c for c in range(256) if c not in b"[]{}")
_DEPTH_STEP = np.zeros(256, np.int8)
_DEPTH_STEP[[ord("["), ord("{")]] = 1
_DEPTH_STEP[[ord("]"), ord("}")]] = -1


def outside_strings(data: bytes) -> bytes:
    """``data`` without its string literals (escaped backslashes and quotes dropped first, so that every remaining
    quote opens or closes a string): what is left are the brackets, commas, numbers and constants."""
    if b"\\" in data:
        data = data.replace(b"\\\\", b"").replace(b'\\"', b"")
    return _STRING.sub(b"", data)


def nesting_depth(outside: bytes) -> int:
    """The deepest nesting of lists and objects in ``outside`` (a text that :func:`outside_strings` returned)."""
    brackets = np.frombuffer(outside.translate(None, _NOT_BRACKETS), np.uint8)
    if not brackets.size:
        return 0
    return int(np.cumsum(_DEPTH_STEP[brackets], dtype=np.int32).max())
