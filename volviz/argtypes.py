"""Command-line argument checking shared by every ``volviz`` command (``volviz.cli``, ``volviz compress``,
``volviz bench NAME``): a parser whose errors are one-line usage errors, and argument types that refuse what cannot
be used (non-numbers, NaN, infinities, values out of range) when the command line is read, before any work starts.

A leaf module: it imports nothing from volviz, so every layer may use it.
"""
from __future__ import annotations

import argparse
import math
from typing import Callable, Optional

#: the largest image a command renders offscreen: a side, and the pixels in all (8192 x 8192 needs about 6 GB here)
MAX_IMAGE_SIDE = 8192
MAX_IMAGE_PIXELS = 64 * 1024 * 1024
#: the longest movie and the most frames a command renders
MAX_MOVIE_SECONDS = 3600.0
MAX_MOVIE_FRAMES = 100_000


class UsageError(Exception):
    """A bad command-line value: reported as one line ``volviz: error: ...`` with exit status 2."""


class UsageParser(argparse.ArgumentParser):
    """An ``ArgumentParser`` whose errors raise ``UsageError`` (one line, no usage dump) instead of exiting."""

    def error(self, message: str) -> None:  # type: ignore[override]
        raise UsageError(message)


def _number(text: str, convert: Callable[[str], float], kind: str) -> float:
    try:
        return convert(text)
    except (ValueError, OverflowError):
        raise argparse.ArgumentTypeError(f"expected {kind}, got {text!r}") from None


def int_in(low: int, high: Optional[int] = None) -> Callable[[str], int]:
    """An argument type: an integer in ``low..high`` (no upper bound when ``high`` is None)."""

    def parse(text: str) -> int:
        value = int(_number(text.strip(), int, "an integer"))
        if value < low or (high is not None and value > high):
            bound = f"at least {low}" if high is None else f"{low}..{high}"
            raise argparse.ArgumentTypeError(f"must be {bound}, got {text!r}")
        return value

    parse.__name__ = "integer"
    return parse


def float_in(low: float, high: float, low_open: bool = False) -> Callable[[str], float]:
    """An argument type: a finite number in ``[low, high]`` (``(low, high]`` when ``low_open``); NaN, infinities and
    non-numbers are refused."""

    def parse(text: str) -> float:
        value = _number(text.strip(), float, "a number")
        if not math.isfinite(value) or value < low or (low_open and value == low) or value > high:
            bound = f"{'more than' if low_open else 'at least'} {low:g} and at most {high:g}"
            raise argparse.ArgumentTypeError(f"must be a number {bound}, got {text!r}")
        return value

    parse.__name__ = "number"
    return parse


def image_size(text: str) -> tuple[int, int]:
    """An argument type: ``WIDTHxHEIGHT`` of an image that can be rendered offscreen (at most ``MAX_IMAGE_SIDE`` a
    side and ``MAX_IMAGE_PIXELS`` in all)."""
    try:
        w, h = (int(v) for v in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected WIDTHxHEIGHT, e.g. 800x600, got {text!r}") from None
    if not (1 <= w <= MAX_IMAGE_SIDE and 1 <= h <= MAX_IMAGE_SIDE) or w * h > MAX_IMAGE_PIXELS:
        raise argparse.ArgumentTypeError(f"image size must be 1..{MAX_IMAGE_SIDE} on each side (at most "
                                         f"{MAX_IMAGE_PIXELS // 2 ** 20} MPixel), got {text!r}")
    return (w, h)


def joined(one: Callable[[str], object], count: int, separator: str) -> Callable[[str], tuple]:
    """An argument type: ``count`` values of the type ``one`` joined by ``separator`` (``joined(int_in(1), 3, "x")``
    reads ``513x513x65``)."""

    def parse(text: str) -> tuple:
        parts = text.lower().split(separator)
        if len(parts) != count:
            raise argparse.ArgumentTypeError(f"expected {count} values joined by {separator!r}, got {text!r}")
        return tuple(one(p) for p in parts)

    parse.__name__ = "values"
    return parse
