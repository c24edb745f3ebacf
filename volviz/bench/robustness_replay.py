"""Every case of ``volviz bench robustness`` reproducible (issue #32): the record of a case and its replay.

A case is a recipe (``robustness.make_mutation``: a truncation point, a header field and its value, or the name of
a random generator) applied to a seed file, so the same recipe on the same seed makes the same damaged file. The
campaign writes one JSON line per case (``--record``): the format, the seed file (its path under the data folder or
the run's written seeds, its SHA-256 and size), the recipe, the campaign's seed, the kind of mutation in words, what
it changed (the size before and after, each run of changed bytes with its offset and the bytes before and after,
and the bits flipped), the damaged file's SHA-256, and both sides' outcomes. ``--replay CASE`` rebuilds exactly that
damaged file, among its seed's other files, checks it against the recorded SHA-256 and reads it as the campaign's
volviz side does (``robustness.rebuild`` / ``replay``, beside the campaign's mutations: this module is the record
alone, below the campaign), so a silent acceptance found by a run can be looked at, fixed and tested.
"""
from __future__ import annotations

import hashlib
import json
import os
from pathlib import Path
from typing import Any, Optional

import numpy as np

#: runs of changed bytes a record lists (a bit flip changes up to 8, a field one; the rest are counted)
MAX_RUNS = 32
#: bytes of one run a record shows (before and after, hexadecimal)
MAX_RUN_BYTES = 64


class ReplayError(Exception):
    """A case that cannot be rebuilt: not in the record, its seed file missing or not the recorded one, or the
    rebuilt bytes differ from the recorded ones."""


def sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def changes(before: bytes, after: bytes) -> dict[str, Any]:
    """What a mutation changed: both sizes, the runs of changed bytes (offset, length before and after, the bytes
    before and after in hexadecimal; at most ``MAX_RUNS`` runs of ``MAX_RUN_BYTES`` shown, the rest counted) and
    every flipped bit as (byte offset, bit) where a changed byte differs in one bit. A file whose size changed (a
    truncation, a field written longer or shorter) is one run: what lies between the common start and end."""
    if len(before) != len(after):
        a, b = np.frombuffer(before, np.uint8), np.frombuffer(after, np.uint8)
        common = min(a.size, b.size)
        start = _first_difference(a[:common], b[:common])
        end = _first_difference(a[::-1][:common - start], b[::-1][:common - start])
        return {"size_before": len(before), "size_after": len(after), "runs_not_shown": 0, "bits": [],
                "runs": [_run(before, after, start, len(before) - end, len(after) - end)]}
    a, b = np.frombuffer(before, np.uint8), np.frombuffer(after, np.uint8)
    where = np.flatnonzero(a != b)
    breaks = np.flatnonzero(np.diff(where) > 1) + 1
    groups = np.split(where, breaks) if where.size else []
    runs = [_run(before, after, int(g[0]), int(g[-1]) + 1, int(g[-1]) + 1) for g in groups[:MAX_RUNS]]
    xor = a[where] ^ b[where]
    single = (xor & (xor - 1)) == 0
    bits = [[int(o), int(x).bit_length() - 1] for o, x in zip(where[single][:256], xor[single][:256])]
    return {"size_before": len(before), "size_after": len(after), "runs": runs,
            "runs_not_shown": max(0, len(groups) - MAX_RUNS), "bits": bits}


def _first_difference(a: np.ndarray, b: np.ndarray) -> int:
    """Where two byte arrays of one length first differ (their length when they do not)."""
    diff = np.flatnonzero(a != b)
    return int(diff[0]) if diff.size else int(a.size)


def _run(before: bytes, after: bytes, start: int, stop_before: int, stop_after: int) -> dict[str, Any]:
    return {"offset": start, "length_before": stop_before - start, "length_after": stop_after - start,
            "before": before[start:stop_before][:MAX_RUN_BYTES].hex(),
            "after": after[start:stop_after][:MAX_RUN_BYTES].hex()}


def encode_recipe(recipe: tuple) -> list:
    """A recipe as JSON (a byte value as ``{"bytes": hex}``)."""
    return [{"bytes": v.hex()} if isinstance(v, bytes) else v for v in recipe]


def decode_recipe(items: list) -> tuple:
    return tuple(bytes.fromhex(v["bytes"]) if isinstance(v, dict) else v for v in items)


def case_record(number: int, seed: int, src: Any, origin: str, recipe: tuple, mutation: Any,
                original: bytes, damaged: bytes) -> dict[str, Any]:
    """The record of one case (its outcomes are added when both sides have read it): ``src`` a campaign's
    ``robustness.Source``, ``mutation`` its ``robustness.Mutation``."""
    return {"case": number, "seed": seed, "format": src.fmt, "origin": origin, "file": src.name,
            "target": src.target, "source_sha256": sha256(original), "recipe": encode_recipe(recipe),
            "kind": mutation.kind, "detail": mutation.detail, "sha256": sha256(damaged),
            **changes(original, damaged)}


class Recorder:
    """The campaign's record: one JSON line per case, written to a temporary file beside ``path`` and moved onto
    it when the campaign ends (a run stopped halfway leaves the earlier record intact, and its own lines in the
    ``.partial`` file)."""

    def __init__(self, path: Optional[Path]) -> None:
        self.path = path
        self._file = None
        if path is not None:
            path.parent.mkdir(parents=True, exist_ok=True)
            self._partial = path.with_name(path.name + ".partial")
            self._file = open(self._partial, "w", encoding="utf-8")

    def write(self, record: dict[str, Any]) -> None:
        if self._file is not None:
            self._file.write(json.dumps(record, separators=(",", ":")) + "\n")
            self._file.flush()

    def close(self) -> None:
        if self._file is not None and self.path is not None:
            self._file.close()
            os.replace(self._partial, self.path)
            self._file = None


def load(record: Path, case: int) -> dict[str, Any]:
    """The line of ``case`` in a campaign's record."""
    try:
        lines = record.read_text(encoding="utf-8").splitlines()
    except OSError as exc:
        raise ReplayError(f"{record}: cannot read the record ({exc.strerror})") from None
    for n, line in enumerate(lines, 1):
        try:
            item = json.loads(line)
        except json.JSONDecodeError:
            raise ReplayError(f"{record}: line {n} is not a JSON case record") from None
        if isinstance(item, dict) and item.get("case") == case:
            return item
    raise ReplayError(f"{record}: no case {case} in the record ({len(lines)} cases)")
