"""A dataset as plain data: ``encode(dataset) -> (header, arrays)`` and ``decode(header, arrays) -> dataset``.

The header is JSON-ready (dicts, lists, strings, numbers) and says what the dataset is: its kind, its scalar fields
(spacing, names, source ...) and, for every array field, the index of the array in the list. The arrays travel
separately as raw buffers (``.npy`` files read with ``allow_pickle=False``), so nothing of a dataset that came from an
untrusted file is ever unpickled. ``decode`` trusts nothing: only the model's dataset kinds, fields of the expected
types, arrays of plain numeric dtypes whose shapes match the header, every index in range; the dataset's own
constructor then checks the rest (shapes against each other, connectivity in range).

A TimeSeries is encoded with its times and its loaded frames; frames not yet loaded are ``None`` and ``lazy`` says
that the series had a loader for them (the isolated reader asks the child for them one by one).
"""
from __future__ import annotations

import math
from typing import Any

import numpy as np

from volviz.model import CurvilinearGrid, Image2D, RegularVolume, TetMesh, TimeSeries, UnstructuredMesh

FORMAT = "volviz-dataset"
VERSION = 1
ALLOWED_DTYPE_KINDS = "biufc"  # bool, signed, unsigned, float, complex: no objects, strings or records
MAX_NDIM = 8

# Each kind's fields and how they are written: "array" (an index into the array list), "arrays" ({name: index}),
# "cells" ([[vtk cell type, index], ...]), "floats" (a list of numbers), "str", "optstr", "optint".
SCHEMAS: dict[str, tuple[type, dict[str, str]]] = {
    "RegularVolume": (RegularVolume, {"data": "array", "spacing": "floats", "origin": "floats", "name": "str",
                                      "source": "str", "arrays": "arrays"}),
    "CurvilinearGrid": (CurvilinearGrid, {"points": "array", "point_data": "arrays", "active": "optstr",
                                          "source": "str", "cell_data": "arrays"}),
    "UnstructuredMesh": (UnstructuredMesh, {"points": "array", "cells": "cells", "point_data": "arrays",
                                            "cell_data": "arrays", "active": "optstr", "source": "str"}),
    "TetMesh": (TetMesh, {"points": "array", "tets": "array", "scalars": "array", "name": "str", "source": "str"}),
    "Image2D": (Image2D, {"data": "array", "spacing": "floats", "origin": "floats", "maxval": "optint",
                          "source": "str"}),
}


class CodecError(ValueError):
    """A dataset that cannot be encoded, or a header that does not describe a valid dataset."""


# -- encoding ----------------------------------------------------------------------------------------------------------
class _Arrays:
    """The array list being built; an array object met twice (a volume's ``data`` that is also in its ``arrays``)
    is stored once and decodes to one shared array again."""

    def __init__(self) -> None:
        self.items: list[np.ndarray] = []
        self._index: dict[int, int] = {}

    def add(self, value: Any, where: str) -> int:
        if not isinstance(value, np.ndarray):
            raise CodecError(f"{where} is a {type(value).__name__}, not a NumPy array")
        if value.dtype.kind not in ALLOWED_DTYPE_KINDS or value.dtype.fields is not None:
            raise CodecError(f"{where} has dtype {value.dtype}, not a plain numeric type")
        key = id(value)
        if key not in self._index:
            self._index[key] = len(self.items)
            self.items.append(value)
        return self._index[key]


def _encode_field(value: Any, how: str, where: str, arrays: _Arrays) -> Any:
    if how == "array":
        return arrays.add(value, where)
    if how == "arrays":
        return {str(name): arrays.add(arr, f"{where}[{name!r}]") for name, arr in dict(value).items()}
    if how == "cells":
        return [[int(cell_type), arrays.add(conn, f"{where} block of type {cell_type}")] for cell_type, conn in value]
    if how == "floats":
        return [float(v) for v in value]
    if how in ("str", "optstr"):
        return None if value is None else str(value)
    if how == "optint":
        return None if value is None else int(value)
    raise AssertionError(how)  # pragma: no cover - the schemas use only the kinds above


def _encode_dataset(dataset: Any, arrays: _Arrays) -> dict:
    name = type(dataset).__name__
    if name not in SCHEMAS or type(dataset) is not SCHEMAS[name][0]:
        raise CodecError(f"the reader returned a {type(dataset).__module__}.{name}, not a volviz dataset "
                         f"({', '.join(SCHEMAS)} or TimeSeries)")
    fields = SCHEMAS[name][1]
    return {"kind": name, **{f: _encode_field(getattr(dataset, f), how, f, arrays) for f, how in fields.items()}}


def encode(dataset: Any) -> tuple[dict, list[np.ndarray]]:
    """``(header, arrays)`` of a model dataset or TimeSeries (its loaded frames only); CodecError for anything else."""
    arrays = _Arrays()
    if isinstance(dataset, TimeSeries) and type(dataset) is TimeSeries:
        body: dict = {"kind": "TimeSeries", "times": [float(t) for t in dataset.times], "source": str(dataset.source),
                      "lazy": dataset.loader is not None,
                      "frames": [None if f is None else _encode_dataset(f, arrays) for f in dataset.frames]}
    else:
        body = _encode_dataset(dataset, arrays)
    specs = [{"dtype": a.dtype.str, "shape": list(a.shape)} for a in arrays.items]
    return {"format": FORMAT, "version": VERSION, "arrays": specs, "dataset": body}, arrays.items


# -- decoding ----------------------------------------------------------------------------------------------------------
def array_specs(header: Any) -> list[tuple[np.dtype, tuple[int, ...]]]:
    """The (dtype, shape) of every array the header announces, validated (before any array is read)."""
    if not isinstance(header, dict) or header.get("format") != FORMAT or header.get("version") != VERSION:
        raise CodecError(f"not a {FORMAT} header of version {VERSION}")
    specs = header.get("arrays")
    if not isinstance(specs, list):
        raise CodecError("the header has no array list")
    out = []
    for i, spec in enumerate(specs):
        if not isinstance(spec, dict) or not isinstance(spec.get("dtype"), str) or not isinstance(spec.get("shape"),
                                                                                                    list):
            raise CodecError(f"array {i}: the header gives no dtype and shape")
        try:
            dtype = np.dtype(spec["dtype"])
        except TypeError:
            raise CodecError(f"array {i}: unknown dtype {spec['dtype']!r}") from None
        if dtype.kind not in ALLOWED_DTYPE_KINDS or dtype.fields is not None:
            raise CodecError(f"array {i}: dtype {dtype} is not a plain numeric type")
        shape = spec["shape"]
        if len(shape) > MAX_NDIM or not all(type(n) is int and n >= 0 for n in shape):
            raise CodecError(f"array {i}: shape {shape} is not a list of at most {MAX_NDIM} sizes")
        out.append((dtype, tuple(shape)))
    return out


def _index(value: Any, arrays: list[np.ndarray], where: str) -> np.ndarray:
    if type(value) is not int or not 0 <= value < len(arrays):
        raise CodecError(f"{where}: {value!r} is not the index of one of the {len(arrays)} arrays")
    return arrays[value]


def _names(value: Any, where: str) -> dict:
    if not isinstance(value, dict) or not all(isinstance(k, str) for k in value):
        raise CodecError(f"{where} is not a mapping of names")
    return value


def _decode_field(value: Any, how: str, where: str, arrays: list[np.ndarray]) -> Any:
    if how == "array":
        return _index(value, arrays, where)
    if how == "arrays":
        return {k: _index(v, arrays, f"{where}[{k!r}]") for k, v in _names(value, where).items()}
    if how == "cells":
        if not isinstance(value, list) or not all(isinstance(b, list) and len(b) == 2 and type(b[0]) is int
                                                  for b in value):
            raise CodecError(f"{where} is not a list of [cell type, array index] pairs")
        return [(t, _index(i, arrays, f"{where} block of type {t}")) for t, i in value]
    if how == "floats":
        if not isinstance(value, list) or not all(type(v) in (int, float) for v in value):
            raise CodecError(f"{where} is not a list of numbers")
        return tuple(float(v) for v in value)
    if how == "optint" and (value is None or type(value) is int):
        return value
    if how == "optstr" and (value is None or isinstance(value, str)):
        return value
    if how == "str" and isinstance(value, str):
        return value
    raise CodecError(f"{where} is {type(value).__name__}, expected {how}")


def _decode_dataset(body: Any, arrays: list[np.ndarray]) -> Any:
    if not isinstance(body, dict) or body.get("kind") not in SCHEMAS:
        kind = body.get("kind") if isinstance(body, dict) else type(body).__name__
        raise CodecError(f"unknown dataset kind {kind!r}")
    cls, fields = SCHEMAS[body["kind"]]
    extra = set(body) - set(fields) - {"kind"}
    if extra or set(fields) - set(body):
        raise CodecError(f"{body['kind']} fields {sorted(body)} are not {sorted(fields)}")
    values = {f: _decode_field(body[f], how, f"{body['kind']}.{f}", arrays) for f, how in fields.items()}
    return cls(**values)


def decode(header: dict, arrays: list[np.ndarray]) -> Any:
    """The dataset a header and its arrays describe; CodecError (or the model's ValueError) if they do not fit.

    A lazy TimeSeries comes back without a loader: the caller attaches one.
    """
    specs = array_specs(header)
    if len(specs) != len(arrays):
        raise CodecError(f"the header announces {len(specs)} arrays, {len(arrays)} were given")
    for i, ((dtype, shape), arr) in enumerate(zip(specs, arrays)):
        if not isinstance(arr, np.ndarray) or arr.dtype != dtype or arr.shape != shape:
            got = f"{arr.dtype} {arr.shape}" if isinstance(arr, np.ndarray) else type(arr).__name__
            raise CodecError(f"array {i} is {got}, the header says {dtype} {shape}")
    body = header.get("dataset")
    if isinstance(body, dict) and body.get("kind") == "TimeSeries":
        return _decode_series(body, arrays)
    return _decode_dataset(body, arrays)


def _decode_series(body: dict, arrays: list[np.ndarray]) -> TimeSeries:
    times, frames = body.get("times"), body.get("frames")
    if not isinstance(times, list) or not all(type(t) in (int, float) and math.isfinite(t) for t in times):
        raise CodecError("TimeSeries.times is not a list of finite numbers")
    if not isinstance(frames, list) or any(isinstance(f, dict) and f.get("kind") == "TimeSeries" for f in frames):
        raise CodecError("TimeSeries.frames is not a list of datasets")
    if not isinstance(body.get("source"), str) or not isinstance(body.get("lazy"), bool):
        raise CodecError("TimeSeries source or lazy flag missing")
    decoded = [None if f is None else _decode_dataset(f, arrays) for f in frames]
    if decoded and decoded[0] is None:
        raise CodecError("TimeSeries frame 0 is missing")
    if not body["lazy"] and any(f is None for f in decoded):
        raise CodecError("TimeSeries has frames that are neither loaded nor loadable")
    return TimeSeries(np.asarray(times, dtype=np.float64), decoded, source=body["source"])
