"""Docstrings say what and why; measured history lives in ``docs/bench/`` (issue #31). Every docstring (module,
class, function, method) of ``volviz`` and ``app`` is read sentence by sentence, and a sentence is measured
history when it holds

- a date (``2026-11-28``) or a commit hash (7-40 hex digits with a letter and a digit);
- a spread of runs: a range of a quantity (``62-78 ms``, ``0.4 to 0.9 s``, ``RMSE 8.8 - 10.9``; not of a percentage:
  a percentile range is a definition);
- a comparison of two readings: ``0.37 s against 0.67 s``, ``1.09 / 1.69 s``, ``0.7 -> 0.3 s``, ``from X to Y``;
- a reading in the past tense: ``took 0.4 s``, ``was 34 ms``;
- the word "measured" and a figure (a quantity with a unit, a ratio ``6.1:1``, ``3x``, an RMSE/PSNR/max reading,
  a number in scientific notation, a pair of readings ``0.06 / 0.60``): what a run gave, not why;
- a figure tied to a machine: ``on llvmpipe``, ``on 2 cores``, ``at load 12``, an H200, "the quiet machine".

A quantity is a number with a unit of time, rate or size (ms, s, fps, MB, GB, dB, %, bit/voxel). What stays: a
figure that is the why of a choice in a few words, a design constant ("a 0.1 s debounce", "4 MB per chunk") or a
stated bound ("RMSE < 2 against the exact reference", "under 5 s", "1 s or more": a figure after <, ≤, >, ≥,
under, below, at most, within, up to, or before "or more"/"or less"), and "measured" without a figure ("the
measured error", "measured in docs/bench/tables.md"). The figures that were moved out are in
``docs/bench/docstring-figures.md`` (or the bench file they belong to), under the module they came from.

``ALLOWED`` names the docstrings (``path:name``) left with history and why; an entry that no longer matches fails,
so the list only shrinks."""
from __future__ import annotations

import ast
import re
from pathlib import Path
from typing import Iterator

import pytest

ROOT = Path(__file__).resolve().parents[1]

_NUM = r"\d+(?:\.\d+)?"
_UNIT = r"(?:ms|µs|us|s|sec|seconds?|minutes?|min|fps|KB|kB|MB|GB|MiB|GiB|dB|%|bits?/voxel)(?![\w/])"
_QTY = rf"{_NUM}\s?{_UNIT}"
_METRIC = r"(?:RMSE|PSNR|max|max abs)"
#: a stated bound: a comparator or its words, then a figure (removed before the rules are applied)
_BOUND = re.compile(rf"(?:[<≤≥]|(?<!-)>|\b(?:under|below|at most|at least|within|up to|less than|more than|over)"
                    rf"\b(?:\s(?:its|the))?)\s*"
                    rf"(?:about\s|~)?{_NUM}(?:e-?\d+)?(?:\s?{_UNIT})?|{_QTY}\s+or\s+(?:more|less)\b")
_MACHINE = (r"\b(?:on|at)\s(?:Mesa\s)?(?:llvmpipe|an?\sH200|the\s(?:quiet|loaded|shared)\s(?:\d-core\s)?machine|"
            r"\d+\scores?|load\s\d)")
_FIGURE = (rf"{_QTY}|\b{_NUM}:1\b|\b{_NUM}\s?x\b(?!\s?\d)|\b{_METRIC}\s(?:of\s)?~?{_NUM}|\b\d(?:\.\d+)?e-\d+\b"
           rf"|\b\d+\.\d+\s/\s\d+(?:\.\d+)?\b")

RULES: dict[str, re.Pattern[str]] = {
    "date": re.compile(r"\b20\d\d-[01]\d-[0-3]\d\b"),
    "commit": re.compile(r"(?<![\w./-])(?=[0-9a-f]*[0-9])(?=[0-9a-f]*[a-f])[0-9a-f]{7,40}(?![\w./-])"),
    "range": re.compile(rf"\b{_NUM}\s?(?:-|–|to)\s?{_NUM}\s?(?!%){_UNIT}|\b{_METRIC}\s~?{_NUM}\s?(?:-|–|to)\s?{_NUM}"),
    "comparison": re.compile(
        rf"(?:{_FIGURE}).{{0,60}}?\b(?:against|vs\.?|versus|instead of|compared with|down from|up from)\s"
        rf".{{0,40}}?(?:{_FIGURE})|{_NUM}\s?(?:->|→)\s?(?:{_FIGURE})|\bfrom\s{_QTY}\sto\s{_QTY}"
        rf"|\b{_NUM}\s?/\s?{_QTY}"),
    "past reading": re.compile(rf"\b(?:took|was|were|spent)\s(?:about\s|only\s|~)?{_QTY}"),
    "measured figure": re.compile(rf"(?i:\bmeasured\b)(?=.*(?:{_FIGURE}))|(?:{_FIGURE})(?=.*(?i:\bmeasured\b))"),
    "machine": re.compile(rf"(?:{_FIGURE}).{{0,80}}?{_MACHINE}|{_MACHINE}.{{0,80}}?(?:{_FIGURE})"),
}

#: where a sentence ends: a full stop, semicolon, question or exclamation mark before white space (a decimal point,
#: a file name's dot and "docs/x.md" stay inside their sentence)
_SENTENCE = re.compile(r"(?<=[.;!?])\s+")

#: docstrings (``path:name``, ``<module>`` for a module's) left with measured history, and why
ALLOWED: dict[str, str] = {
}


def history(docstring: str) -> list[str]:
    """The measured history in ``docstring`` (module docstring): ``"rule: matched text"`` for each match."""
    text = _BOUND.sub("BOUND", " ".join(docstring.split()))
    return [f"{name}: {m.group(0)}" for sentence in _SENTENCE.split(text) for name, rule in RULES.items()
            for m in rule.finditer(sentence)]


def docstrings(root: Path = ROOT) -> Iterator[tuple[str, str]]:
    """(``path:name``, docstring) of every module, class, function and method of ``volviz`` and ``app``."""
    for package in ("volviz", "app"):
        for path in sorted((root / package).rglob("*.py")):
            tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
            for node in ast.walk(tree):
                if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
                    doc = ast.get_docstring(node, clean=False)
                    if doc:
                        name = node.name if not isinstance(node, ast.Module) else "<module>"
                        yield f"{path.relative_to(root).as_posix()}:{name}", doc


def found(root: Path = ROOT) -> dict[str, list[str]]:
    """Every docstring with measured history, by ``path:name``."""
    out: dict[str, list[str]] = {}
    for key, doc in docstrings(root):
        hits = history(doc)
        if hits:
            out.setdefault(key, []).extend(hits)
    return out


def test_no_docstring_carries_measured_history() -> None:
    new = {key: hits for key, hits in found().items() if key not in ALLOWED}
    assert not new, "measured history in docstrings (move it to docs/bench/, keep the why):\n" + "\n".join(
        f"{key}: {hits}" for key, hits in sorted(new.items()))


def test_allowed_entries_still_carry_history() -> None:
    stale = sorted(set(ALLOWED) - set(found()))
    assert not stale, "no history left; remove from ALLOWED:\n" + "\n".join(stale)


@pytest.mark.parametrize("text", [
    "Written on 2026-11-28 after the flight.",
    "The fix of 4701f50 keeps the order.",
    "Each frame took 0.4 s to draw.",
    "The mip-mapped terrain cost 62-78 ms per frame.",
    "The CPU path: 0.37 s against 0.67 s for the GL pass.",
    "Per frame 1.09 / 1.69 s (CPU / GL).",
    "volviz info: 0.7 -> 0.3 s.",
    "Measured on embryo: 6.10:1 lossless.",
    "An error of 3e-16 (measured on a 41x41 grid).",
    "Each render of a big scene is 0.5 s on llvmpipe.",
    "The frames stood RMSE 8.8 - 10.9 from the reference.",
    "The app's start to its first frame went from 2.1 s to 1.4 s.",
])
def test_the_rule_sees_history(text: str) -> None:
    assert history(text), text


@pytest.mark.parametrize("text", [
    "A 0.1 s debounce keeps the window responsive.",
    "Chunks of 4 MB, so a read never holds more than that.",
    "The image stays within RMSE < 2 against the exact reference.",
    "Every file reaches its first image in under 5 s.",
    "Each refusal that took 1 s or more is read again.",
    "The error budget is checked against the measured error of the current view.",
    "Its error grows with k (measured in docs/bench/tables.md).",
    "The weights of Eq. 11.6, digest §8-9, a 64 x 64 x 128 table.",
    "The azimuth, measured counter-clockwise from +x.",
    "Absolute error < 1e-13 over the whole grid.",
])
def test_the_rule_keeps_the_why(text: str) -> None:
    assert history(text) == [], text
