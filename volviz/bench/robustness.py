"""Benchmark: a standing fuzz campaign against every reader (``volviz bench robustness``).

Every file in the shared data folder is mutated (bit flips; truncation at every header boundary; numeric header
fields set to 0, -1, 2^31-1, 2^63-1, NaN and non-numbers, as text or as binary integers; XML attributes swapped,
flipped and enlarged; HDF5 metadata damaged, byte-wise and through h5py) and each mutated file is read twice, side
by side: by ``volviz.io.read`` (isolated as it is by default) and by VTK's own reader of the same format. Each side
runs in a long-lived worker child with a memory limit, and the bench waits for each answer with a time limit, so a
crash, an abort, a hang or a memory blow-up of either side is counted, not fatal (the worker is then replaced).

Per format and side the report counts: cases, clean errors (volviz: ``ReadError``; VTK: an error message or an
empty output), other exceptions, crashes, hangs, memory blow-ups, silent garbage (a read that succeeds although the
truncated file lost data, or with a grid size other than the original's, or inconsistent / non-finite geometry),
reads "valid as damaged" (a truncated file both sides read to the same content: ``robustness_agree``) and the
slowest refusal. Writes a section of ``docs/reliability.md`` (or ``--out FILE``) and optionally ``--json``.

Targets (volviz issue 15), over at least 10,000 cases: 0 crashes or hangs of the volviz process, 0 exceptions other
than volviz's own, 0 silent garbage, every refusal under 1 s. The mutations are also used by the tests
(``tests/test_io_fuzz_readers.py``).
"""
from __future__ import annotations

import fnmatch
import importlib
import json
import math
import os
import platform
import random
import re
import resource
import shlex
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import threading
import time
import warnings
import zlib
from collections import Counter, defaultdict
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Optional

import numpy as np

from volviz.argtypes import UsageParser, int_in
from volviz.bench.robustness_agree import content_volviz, content_vtk, valid_as_damaged
from volviz.bench.robustness_replay import Recorder, ReplayError, case_record, decode_recipe, load, sha256

DEFAULT_DATA = Path(os.environ.get("VOLVIZ_DATA", Path(__file__).resolve().parents[2].parent / "shared" / "data"))
REPORT = Path(__file__).resolve().parents[2] / "docs" / "reliability.md"
SECTION = "## Fuzz campaign"
REFUSAL_TARGET_S = 1.0
VTK_SECONDS = 5.0

#: what a numeric header field is set to (text), and as a binary integer
TEXT_VALUES = (b"0", b"-1", b"2147483647", b"9223372036854775807", b"nan", b"abc", b"-2147483648", b"4294967295",
               b"1e308", b"")
INT_VALUES = (0, -1, 2**31 - 1, 2**63 - 1, -2**31, 2**32 - 1)
_NUMBER = re.compile(rb"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?")
_TAG = re.compile(rb"<[A-Za-z][^<>]{0,4000}>")
_ATTR = re.compile(rb'([A-Za-z_]+)="([^"]{0,4000})"')
_ALTERNATIVES = {b"LittleEndian": b"BigEndian", b"BigEndian": b"LittleEndian", b"UInt32": b"UInt64",
                 b"UInt64": b"UInt32", b"binary": b"ascii", b"ascii": b"appended", b"appended": b"binary",
                 b"Float32": b"Float64", b"Float64": b"Int8", b"Int64": b"Int32", b"Int32": b"UInt8",
                 b"UInt8": b"Float64", b"vtkZLibDataCompressor": b"vtkLZ4DataCompressor"}


# -- the files ---------------------------------------------------------------------------------------------------------
@dataclass
class Source:
    """One file of the data folder to mutate, and how both sides read it.

    ``target`` is the file read (the mutated file itself, or the descriptor beside it: a .mhd for its .raw, the
    ``case.foam`` of an OpenFOAM case, the PLOT3D grid for its solution); ``links`` are the unchanged files put
    beside the mutated one (symbolic links); ``layout`` is how its header looks ("text", "xml", "binary", "hdf5",
    "none"); ``endian`` the byte order of binary header fields; ``vtk`` the name of VTK's reader recipe (None: VTK
    has no reader of the format); ``mirror`` the folder of a dataset of several files (a Zarr folder, a collection
    and its pieces), put beside the mutated file as it is (``target`` is then relative to it)."""

    fmt: str
    path: Path
    root: Path
    target: str
    links: dict[str, Path] = field(default_factory=dict)
    options: dict = field(default_factory=dict)
    vtk_options: dict = field(default_factory=dict)
    layout: str = "text"
    endian: str = ">"
    vtk: Optional[str] = None
    header_end: int = 0
    mirror: Optional[Path] = None


    @property
    def name(self) -> str:
        return str(self.path.relative_to(self.root))


#: format label, VTK recipe, header layout, binary byte order, by file-name pattern
_KINDS = (
    ("*.pvm*", "pvm", None, "text", ">"), ("*.slc", "slc", "slc", "text", ">"), ("*.pgm", "pnm", "pnm", "text", ">"),
    ("*.ppm", "pnm", "pnm", "text", ">"), ("*.mhd", "metaimage", "mhd", "text", ">"),
    ("*.raw", "metaimage", "mhd", "none", ">"), ("*.dem", "dem", "dem", "text", ">"),
    ("*xyz.bin", "plot3d", "plot3d", "binary", ">"), ("*q.bin", "plot3d", "plot3d", "binary", ">"),
    ("*.vtk", "vtk-legacy", "vtk-legacy", "text", ">"), ("*.vti", "vti", "vti", "xml", "<"),
    ("*.vtu", "vtu", "vtu", "xml", "<"), ("*.vtkhdf", "vtkhdf", "vtkhdf", "hdf5", "<"),
    ("*.jpeg", "jpeg", "jpeg", "binary", ">"), ("*.ex2", "exodus", "exodus", "binary", ">"),
    ("*.cgns", "cgns", "cgns", "binary", ">"), ("*.nc", "netcdf", "netcdf", "binary", ">"),
    ("quarter.*", "raw", "raw", "none", "<"), ("*.tec", "tecplot", "tecplot", "text", ">"),
    ("*.cas.h5", "fluent-cff", "fluent-cff", "hdf5", "<"), ("*.dat.h5", "fluent-cff", "fluent-cff", "hdf5", "<"),
    ("*.xdmf", "xdmf", "xdmf", "xml", "<"), ("*.h5", "xdmf", "xdmf", "hdf5", "<"),
)


def _header_end(data: bytes, layout: str) -> int:
    """Bytes at the start holding the header: the printable prefix of a text file (at most 4 KB, the DEM's first
    records included), the first KB of a binary one, the tags of an XML file up to 64 KB."""
    if layout == "none":
        return 0
    if layout in ("binary", "hdf5", "vvz"):
        return min(len(data), 1024)
    limit = 65536 if layout in ("xml", "json") else 4096
    for i, byte in enumerate(data[:limit]):
        if byte >= 127 or (byte < 32 and byte not in (9, 10, 13)):
            return i
    return min(len(data), limit)


def sources(root: Path) -> list[Source]:
    """Every file under ``root`` as a Source (OpenFOAM case files are read through their ``case.foam``)."""

    found: list[Source] = []
    for folder, dirs, files in os.walk(root):
        dirs.sort()
        here = Path(folder)
        foam = next((p / "case.foam" for p in [here, *here.parents] if (p / "case.foam").exists()), None)
        for name in sorted(files):
            path = here / name
            if foam is not None:
                if name != "case.foam":
                    found.append(Source("openfoam", path, root, "", layout="text", vtk="openfoam"))
                continue
            kind = next((k for k in _KINDS if fnmatch.fnmatch(name.lower(), k[0])), None)
            if kind is None:
                continue
            src = Source(kind[1], path, root, name, layout=kind[3], endian=kind[4], vtk=kind[2])
            if _complete(src):
                found.append(src)
    for src in found:
        src.header_end = _header_end(src.path.read_bytes()[:65536], src.layout)
    return found


def made_sources(folder: Path, formats: list[str] | None = None) -> list[Source]:
    """Sources of the formats the data folder lacks, written into ``folder`` (``volviz.bench.robustness_made``,
    and the seeds of several files each of ``volviz.bench.robustness_formats``: one Source per file they damage)."""
    # another bench's module (it loads VTK or its own dependencies): only for this case
    from volviz.bench.robustness_formats import write_seeds
    from volviz.bench.robustness_made import MADE, write_made

    found = []
    for fmt, path in write_made(folder, formats).items():
        _name, _write, layout, endian, vtk = MADE[fmt]
        found.append(Source(fmt, path, folder, path.name, layout=layout, endian=endian, vtk=vtk))
    for seed, where in write_seeds(folder / "seeds", formats):
        found += [Source(seed.fmt, where / rel, folder, seed.target, layout=layout, endian=endian, vtk=seed.vtk,
                         mirror=where) for rel, layout, endian in seed.mutate]
    for src in found:
        src.header_end = _header_end(src.path.read_bytes()[:65536], src.layout)
    return found


def _complete(src: Source) -> bool:
    """The companions and options of the formats read as pairs or with options; False for a file that is not
    read on its own and has no partner here (an HDF5 file with no XDMF file beside it)."""
    folder, name = src.path.parent, src.path.name
    if src.fmt in ("xdmf", "fluent-cff"):
        partners = {".xdmf": [".h5"], ".h5": [".xdmf"], ".cas.h5": [".dat.h5"], ".dat.h5": [".cas.h5"]}
        ending = next(e for e in (".cas.h5", ".dat.h5", ".xdmf", ".h5") if name.endswith(e))
        stem = name[:-len(ending)]
        others = [stem + e for e in partners[ending] if (folder / (stem + e)).exists()]
        if src.fmt == "xdmf" and ending == ".h5" and not others:
            return False
        src.links.update({o: folder / o for o in others})
        if ending in (".h5", ".dat.h5"):
            src.target = others[0] if others else name
    elif src.fmt == "metaimage" and name.endswith(".raw"):
        src.target = name[:-4] + ".mhd"
        src.links[src.target] = folder / src.target
    elif src.fmt == "metaimage":
        raw = re.search(rb"ElementDataFile\s*=\s*(\S+)", src.path.read_bytes())
        if raw:
            src.links[raw.group(1).decode()] = folder / raw.group(1).decode()
    elif src.fmt == "plot3d":
        grid, q = name.replace("q.bin", "xyz.bin"), name.replace("xyz.bin", "q.bin")
        src.links.update({n: folder / n for n in (grid, q) if n != name})
        src.target = grid
        src.options = {"q": q}
    elif src.fmt == "raw":
        src.options = {"dims": [64, 64, 1], "dtype": "uint16", "byteorder": "little"}
    return True


# -- mutations ---------------------------------------------------------------------------------------------------------
@dataclass
class Mutation:
    """A change to one file: ``kind`` (bitflip, truncate, field, xml-swap, xml-flip, xml-enlarge, hdf5-meta,
    hdf5-field), what it did in words, and the new bytes (None for hdf5-field, applied to the written file)."""

    kind: str
    detail: str
    data: Optional[bytes]
    edit: Optional[Callable[[Path], None]] = None


def number_spans(data: bytes, end: int) -> list[tuple[int, int]]:
    """(start, stop) of every number in the first ``end`` bytes."""
    return [m.span() for m in _NUMBER.finditer(data, 0, end)]


def xml_attributes(data: bytes) -> list[tuple[int, int]]:
    """(start, stop) of every attribute value of every XML tag (appended raw data excluded)."""
    stop = data.find(b"<AppendedData")
    spans = []
    for tag in _TAG.finditer(data, 0, len(data) if stop < 0 else stop + 200):
        for m in _ATTR.finditer(data, tag.start(), tag.end()):
            spans.append(m.span(2))
    return spans


def boundaries(src: Source, data: bytes) -> list[int]:
    """Where a header ends a part: after each line, tag, word (text and XML headers), 4-byte field (binary headers),
    record (DEM: 1024 bytes); plus the header's end, the middle and one byte short of the whole file."""
    end = max(src.header_end, 0)
    cuts: set[int] = {0, end, len(data) // 2, len(data) - 1}
    if src.layout in ("text", "xml", "json"):
        cuts.update(m.end() for m in re.finditer(rb"[\n> ]", data[:end]))
    elif src.layout in ("binary", "hdf5", "vvz"):
        cuts.update(range(0, min(end, 256), 4))
    if src.fmt == "dem":
        cuts.update(range(1024, min(len(data), 16384), 1024))
    if src.layout == "xml":
        for start, stop in xml_attributes(data)[:200]:
            cuts.update((start, stop))
    return sorted(c for c in cuts if 0 <= c < len(data))


def flip_bits(data: bytes, rng: random.Random, end: int) -> Mutation:
    out = bytearray(data)
    where = []
    for _ in range(rng.randint(1, 8)):
        pos = rng.randrange(end) if end and rng.random() < 0.6 else rng.randrange(len(out))
        out[pos] ^= 1 << rng.randrange(8)
        where.append(pos)
    return Mutation("bitflip", f"bits flipped at {sorted(where)}", bytes(out))


def truncate(data: bytes, at: int) -> Mutation:
    return Mutation("truncate", f"cut at byte {at} of {len(data)}", data[:at])


def set_field(src: Source, data: bytes, rng: random.Random, index: int | None = None,
              value: Any = None) -> Optional[Mutation]:
    """A numeric header field set to one of the values (text headers), or a 4/8-byte integer or a NaN double
    written over a field of a binary header."""
    if src.layout in ("binary", "hdf5", "vvz"):
        end = max(4, min(src.header_end, len(data)) - 8)
        pos = (rng.randrange(end) // 4) * 4 if index is None else index
        value = rng.choice((*INT_VALUES, "nan")) if value is None else value
        if value == "nan":
            raw = struct.pack(src.endian + "d", float("nan"))
        elif -2**31 <= value < 2**32 and rng.random() < 0.7:
            raw = struct.pack(src.endian + ("i" if value < 2**31 else "I"), value)
        else:
            raw = struct.pack(src.endian + ("q" if value < 2**63 else "Q"), value)
        out = data[:pos] + raw + data[pos + len(raw):]
        return Mutation("field", f"binary field at byte {pos} set to {value}", out)
    spans = number_spans(data, src.header_end) if src.layout in ("text", "json") else [
        s for a in xml_attributes(data) for s in ((a[0] + m.start(), a[0] + m.end())
                                                   for m in _NUMBER.finditer(data[a[0]:a[1]]))]
    if not spans:
        return None
    start, stop = spans[rng.randrange(len(spans)) if index is None else index % len(spans)]
    new = rng.choice(TEXT_VALUES) if value is None else value
    return Mutation("field", f"field {data[start:stop][:20]!r} at byte {start} set to {new!r}",
                    data[:start] + new + data[stop:])


def xml_mutation(data: bytes, rng: random.Random, kind: str) -> Optional[Mutation]:
    """``xml-swap``: two attribute values exchanged; ``xml-flip``: a value's words reversed or a keyword replaced
    by another (byte order, header type, format, data type); ``xml-enlarge``: a number multiplied by up to 2^31,
    raised by one, or a value repeated thousands of times."""
    spans = xml_attributes(data)
    if len(spans) < 2:
        return None
    a = spans[rng.randrange(len(spans))]
    old = data[a[0]:a[1]]
    if kind == "xml-swap":
        b = spans[rng.randrange(len(spans))]
        (a, b) = sorted((a, b))
        if a == b or a[1] > b[0]:
            return None
        new = data[:a[0]] + data[b[0]:b[1]] + data[a[1]:b[0]] + old + data[b[1]:]
        return Mutation(kind, f"attribute values {old[:20]!r} and {data[b[0]:b[1]][:20]!r} swapped", new)
    if kind == "xml-flip":
        value = _ALTERNATIVES.get(old) or b" ".join(reversed(old.split())) or b"-"
    else:
        numbers = list(_NUMBER.finditer(old))
        how = rng.random()
        if numbers and how < 0.7:
            m = numbers[rng.randrange(len(numbers))]
            factor = rng.choice((2, 1000, 2**20, 2**31))
            try:
                big = str(int(m.group()) * factor + rng.choice((0, 1))).encode()
            except ValueError:
                big = m.group() + b"e300"
            value = old[:m.start()] + big + old[m.end():]
        else:
            value = (old + b" ") * rng.choice((2, 1000, 20000))
    return Mutation(kind, f"attribute {old[:20]!r} -> {value[:20]!r} ({len(value)} bytes)",
                    data[:a[0]] + value + data[a[1]:])


def hdf5_object_addresses(path: Path) -> list[int]:
    """File addresses of the object headers of every group and dataset of an HDF5 file (its metadata)."""
    # h5py: only the robustness seeds in its format need it (imported where they are written)
    import h5py

    found: list[int] = [0]
    with h5py.File(path, "r") as f:
        def visit(_name: str, obj: Any) -> None:
            found.append(h5py.h5o.get_info(obj.id).addr)
        f.visititems(visit)
    return sorted(set(found))


def hdf5_meta(data: bytes, addresses: list[int], rng: random.Random) -> Mutation:
    """Bytes of the superblock or an object header overwritten (a flipped bit, a zero, 0xFF, a large count)."""
    out = bytearray(data)
    base = rng.choice(addresses)
    pos = min(len(out) - 8, base + rng.randrange(96))
    how = rng.randrange(4)
    if how == 0:
        out[pos] ^= 1 << rng.randrange(8)
    elif how == 1:
        out[pos:pos + 4] = b"\0\0\0\0"
    elif how == 2:
        out[pos:pos + 4] = b"\xff\xff\xff\xff"
    else:
        out[pos:pos + 8] = struct.pack("<q", rng.choice(INT_VALUES[1:4]))
    return Mutation("hdf5-meta", f"object header at {base}: byte {pos} damaged ({how})", bytes(out))


def hdf5_field(path: Path, rng: random.Random) -> Optional[Mutation]:
    """A value of one of the VTKHDF count/offset/extent datasets or attributes set through h5py (0, -1, 2^31-1,
    2^63-1, NaN) -- a file whose HDF5 structure is intact and whose VTKHDF content lies (None: the file has no
    numeric dataset or attribute)."""
    # h5py: only the robustness seeds in its format need it (imported where they are written)
    import h5py

    with h5py.File(path, "r") as f:
        names: list[str] = []
        f.visititems(lambda n, o: names.append(n) if isinstance(o, h5py.Dataset) and o.size and o.dtype.kind in "iuf"
                     and o.ndim <= 3 else None)
        attrs = [(n, a) for n in ["", *names] for a in (f[n] if n else f).attrs
                 if np.asarray((f[n] if n else f).attrs[a]).dtype.kind in "iuf"]
    if not names and not attrs:
        return None
    choice = rng.random()
    value = rng.choice((*INT_VALUES[:4], "nan"))
    if attrs and (choice < 0.25 or not names):
        obj, attr = rng.choice(attrs)

        def edit_attribute(p: Path) -> None:
            with h5py.File(p, "r+") as f:
                target = f[obj] if obj else f
                old = np.array(target.attrs[attr])
                flat = old.reshape(-1).copy()
                flat[rng.randrange(flat.size)] = _cast(value, flat.dtype)
                target.attrs[attr] = flat.reshape(old.shape)
        return Mutation("hdf5-field", f"attribute {obj}/{attr} element set to {value}", None, edit_attribute)
    name = rng.choice([n for n in names if re.search(r"Number|Offset|Types|Steps|Parts|Connectivity", n)] or names)

    def edit(p: Path) -> None:
        with h5py.File(p, "r+") as f:
            ds = f[name]
            idx = tuple(rng.randrange(s) for s in ds.shape)
            ds[idx] = _cast(value, ds.dtype)
    return Mutation("hdf5-field", f"dataset {name} element set to {value}", None, edit)


def _cast(value: Any, dtype: Any) -> Any:

    dtype = np.dtype(dtype)
    if value == "nan":
        return np.nan if dtype.kind == "f" else np.iinfo(dtype).max
    if dtype.kind == "f":
        return float(value)
    info = np.iinfo(dtype)
    return np.array(value).astype(np.int64 if value < 2**63 else np.uint64).astype(dtype) \
        if not info.min <= value <= info.max else value


RANDOM_KINDS = {"text": ("bitflip", "field", "field", "truncate"), "none": ("bitflip", "truncate"),
                "binary": ("bitflip", "field", "truncate"), "xml": ("bitflip", "field", "xml-swap", "xml-flip",
                                                                    "xml-enlarge", "truncate"),
                "hdf5": ("bitflip", "hdf5-meta", "hdf5-meta", "hdf5-field", "hdf5-field", "truncate"),
                "vvz": ("bitflip", "field", "truncate", "vvz-meta", "vvz-meta", "vvz-table"),
                "json": ("bitflip", "field", "truncate", "json", "json")}


def random_mutation(src: Source, data: bytes, rng: random.Random, addresses: list[int] | None = None,
                    kind: str | None = None) -> Mutation:
    """One random mutation of the kinds that fit the file's layout (a bit flip where a kind does not apply)."""
    kind = kind or rng.choice(RANDOM_KINDS[src.layout])
    found: Optional[Mutation] = None
    if kind == "truncate":
        cuts = boundaries(src, data)
        found = truncate(data, rng.choice(cuts) if rng.random() < 0.7 else rng.randrange(len(data)))
    elif kind == "field":
        found = set_field(src, data, rng)
    elif kind.startswith("xml"):
        found = xml_mutation(data, rng, kind)
    elif kind == "hdf5-meta":
        found = hdf5_meta(data, addresses or [0], rng)
    elif kind == "hdf5-field":
        found = hdf5_field(src.path, rng)
    elif kind.startswith("vvz") or kind == "json":
        # another bench's module (it loads VTK or its own dependencies): only for this case
        from volviz.bench.robustness_formats import json_mutation, vvz_mutation

        made = json_mutation(data, rng) if kind == "json" else vvz_mutation(data, rng, kind)
        found = Mutation(kind, *made) if made else None
    return found or flip_bits(data, rng, src.header_end)


def systematic_recipes(src: Source, data: bytes) -> list[tuple]:
    """The systematic cases as recipes (a few numbers each, turned into bytes by ``make_mutation`` when the case
    runs): truncation at every header boundary and every text header field set to every value (the first 40)."""
    found: list[tuple] = [("truncate", at) for at in boundaries(src, data)]
    if src.layout in ("text", "json"):
        for i in range(min(40, len(number_spans(data, src.header_end)))):
            found += [("field", i, v) for v in TEXT_VALUES]
    return found


def make_mutation(src: Source, data: bytes, recipe: tuple, addresses: list[int] | None = None) -> Mutation:
    """The mutation a recipe describes: ``("truncate", at)``, ``("field", index, value)`` or ``("random", seed)``
    (a random mutation drawn with its own generator, so a case is the same whenever it is made)."""
    if recipe[0] == "truncate":
        return truncate(data, recipe[1])
    if recipe[0] == "field":
        found = set_field(src, data, random.Random(0), recipe[1], recipe[2])
        if found is not None:
            return found
    return random_mutation(src, data, random.Random(str(recipe[-1])), addresses)


def systematic(src: Source, data: bytes) -> list[Mutation]:
    """Truncation at every header boundary and every text header field set to every value (the first 40 fields)."""
    return [make_mutation(src, data, r) for r in systematic_recipes(src, data)]


def cases(srcs: list[Source], total: int, seed: int) -> list[tuple[Source, tuple]]:
    """``total`` cases spread evenly over the formats (round-robin), within a format over its files; each file's
    systematic mutations first, then random ones. A case is a recipe (``make_mutation``): the mutated bytes are made
    only when the case runs, so the plan of 10,000 cases takes kilobytes, not gigabytes."""
    by_fmt: dict[str, list[Source]] = defaultdict(list)
    for s in srcs:
        by_fmt[s.fmt].append(s)
    per_fmt = {f: total // len(by_fmt) + (i < total % len(by_fmt)) for i, f in enumerate(sorted(by_fmt))}
    out: list[tuple[Source, tuple]] = []
    for fmt, count in per_fmt.items():
        files = by_fmt[fmt]
        shares = [count // len(files) + (i < count % len(files)) for i in range(len(files))]
        for src, share in zip(files, shares):
            if share == 0:
                continue
            rng = random.Random(f"{seed}:{src.name}")
            fixed = systematic_recipes(src, src.path.read_bytes())
            rng.shuffle(fixed)
            chosen = fixed[: share // 2]
            chosen += [("random", f"{seed}:{src.name}:{k}") for k in range(share - len(chosen))]
            out += [(src, r) for r in chosen]
    random.Random(seed).shuffle(out)
    return out


# -- the two sides: workers --------------------------------------------------------------------------------------------
def fingerprint_volviz(dataset: Any) -> dict:
    """Grid size, a CRC of every array, and whether the dataset is consistent: it survives the isolation codec's
    checks (shapes, dtypes, indices) and its spacing and origin are finite."""
    # the readers (registry and plugins): loaded when a case first reads a file
    from volviz.io.isolated.codec import CodecError, decode, encode

    frames = [dataset.frame(i) for i in frames_to_read(len(dataset))] \
        if getattr(dataset, "kind", "") == "time series" else [dataset]
    problem, crc, n = "", 0, 0
    content = []
    for frame in frames:
        content.append(content_volviz(frame))
        try:
            header, arrays = encode(frame)
            decode(header, arrays)
        except (CodecError, ValueError, TypeError) as exc:
            problem, arrays = f"inconsistent: {exc}", []
        for name in ("spacing", "origin"):
            values = getattr(frame, name, None)
            if values is not None and not all(math.isfinite(float(v)) for v in values):
                problem = f"{name} {tuple(values)} is not finite"
        for a in arrays:
            crc = zlib.crc32(np.ascontiguousarray(a).tobytes(), crc)
        n += int(getattr(frame, "n_points", 0))
    return {"n_points": n, "crc": crc, "problem": problem, "content": content}


def frames_to_read(count: int) -> list[int]:
    """The frames of a time series a case reads: all of up to 30, else the first two and the last."""
    return list(range(count)) if count <= 30 else [0, 1, count - 1]


#: VTK's reader of each format: (module, class); imported alone, so a replaced worker starts quickly
VTK_READERS = {"slc": ("vtkIOImage", "vtkSLCReader"), "pnm": ("vtkIOImage", "vtkPNMReader"),
               "mhd": ("vtkIOImage", "vtkMetaImageReader"), "dem": ("vtkIOImage", "vtkDEMReader"),
               "jpeg": ("vtkIOImage", "vtkJPEGReader"), "raw": ("vtkIOImage", "vtkImageReader2"),
               "vtk-legacy": ("vtkIOLegacy", "vtkDataSetReader"), "vti": ("vtkIOXML", "vtkXMLImageDataReader"),
               "vtu": ("vtkIOXML", "vtkXMLUnstructuredGridReader"), "vtkhdf": ("vtkIOHDF", "vtkHDFReader"),
               "exodus": ("vtkIOExodus", "vtkExodusIIReader"), "cgns": ("vtkIOCGNSReader", "vtkCGNSReader"),
               "netcdf": ("vtkIONetCDF", "vtkNetCDFCFReader"), "plot3d": ("vtkIOParallel", "vtkMultiBlockPLOT3DReader"),
               "openfoam": ("vtkIOGeometry", "vtkOpenFOAMReader"), "tiff": ("vtkIOImage", "vtkTIFFReader"),
               "nifti": ("vtkIOImage", "vtkNIFTIImageReader"), "dicom": ("vtkIOImage", "vtkDICOMImageReader"),
               "mrc": ("vtkIOImage", "vtkMRCReader"), "nrrd": ("vtkIOImage", "vtkNrrdReader"),
               "xdmf": ("vtkIOXdmf2", "vtkXdmfReader"), "tecplot": ("vtkIOGeometry", "vtkTecplotReader"),
               "ensight": ("vtkIOEnSight", "vtkGenericEnSightReader"), "avs": ("vtkIOGeometry", "vtkAVSucdReader"),
               "minc": ("vtkIOMINC", "vtkMINCImageReader"), "fluent-cff": ("vtkIOFLUENTCFF", "vtkFLUENTCFFReader"),
               "xyz": ("vtkIOLegacy", "vtkSimplePointsReader")}


def _vtk_reader(recipe: str, path: str, options: dict) -> Any:

    module, name = VTK_READERS[recipe]
    r = getattr(importlib.import_module(f"vtkmodules.{module}"), name)()
    folder = os.path.dirname(path)
    if recipe == "plot3d":
        r.SetXYZFileName(path)
        r.SetQFileName(os.path.join(folder, options["q"]))
        r.AutoDetectFormatOn()
        return r
    if recipe == "ensight":
        r.SetCaseFileName(path)
        return r
    r.SetFileName(path)
    if recipe == "avs":
        r.SetBinaryFile(open(path, "rb").read(1) == b"\x07")
    if recipe == "raw":
        r.SetDataScalarTypeToUnsignedShort()
        r.SetDataByteOrderToLittleEndian()
        r.SetDataExtent(0, 63, 0, 63, 0, 0)
    return r


def fingerprint_vtk(output: Any) -> dict:
    """Points of every leaf of VTK's output, a CRC of the arrays (coordinates, point and cell data) and the
    output's ``content`` (``robustness_agree``)."""
    # VTK's readers and NumPy bridge: only for the files VTK reads
    from vtkmodules.util.numpy_support import vtk_to_numpy
    from vtkmodules.vtkCommonDataModel import vtkDataSet

    leaves = []
    if output.IsA("vtkCompositeDataSet"):
        it = output.NewIterator()
        it.InitTraversal()
        while not it.IsDoneWithTraversal():
            leaves.append(it.GetCurrentDataObject())
            it.GoToNextItem()
    else:
        leaves = [output]
    n, crc = 0, 0
    leaves = [leaf for leaf in leaves if isinstance(leaf, vtkDataSet)]
    for leaf in leaves:
        n += leaf.GetNumberOfPoints()
        arrays = [leaf.GetPoints().GetData()] if hasattr(leaf, "GetPoints") and leaf.GetPoints() else []
        for data in (leaf.GetPointData(), leaf.GetCellData()):
            arrays += [data.GetArray(i) for i in range(data.GetNumberOfArrays())]
        for a in arrays:
            if a is not None:
                crc = zlib.crc32(vtk_to_numpy(a).tobytes(), crc)
    return {"n_points": n, "crc": crc, "problem": "", "content": content_vtk(leaves)}


def _serve_volviz(request: dict) -> dict:
    # the readers (registry and plugins): loaded when a case first reads a file
    import volviz.io as vio
    from volviz.io import isolated

    options = dict(request["options"])
    if "q" in options:
        options["q"] = os.path.join(os.path.dirname(request["path"]), options["q"])
    if "dims" in options:
        options["dims"] = tuple(options["dims"])
    # the kernels (Numba) of this case only: a bench loads what its cases run
    from volviz.regular.container import CorruptBrickWarning

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("ignore")
        for stated in (vio.ReadWarning, CorruptBrickWarning):  # a doubt the reader states is not silent
            warnings.simplefilter("always", stated)
        try:
            result = read_as_user(request["path"], options)
            warned = next((str(w.message)[:300] for w in caught
                           if issubclass(w.category, (vio.ReadWarning, CorruptBrickWarning))), "")
            return {"status": "ok", **fingerprint_volviz(result), "warned": warned}
        except vio.ReadError as exc:  # naming the file read or the file beside it that is wrong
            return {"status": "error", "message": str(exc)[:300],
                    "named": str(exc).startswith(os.path.dirname(request["path"]))}
        finally:
            isolated.prewarm()  # a reader child that crashed is replaced now, not in the next case's time


def read_as_user(path: str, options: dict) -> Any:
    """What the app does with a file: ``volviz.io.read``, or the ``.vvz`` codec's decoder for volviz's own
    compressed volumes (``volviz.scene.datasets``)."""
    # the readers (registry and plugins): loaded when a case first reads a file
    import volviz.io as vio

    if path.lower().endswith(".vvz"):
        # the kernels (Numba) of this case only: a bench loads what its cases run
        from volviz.regular.codec import decompress

        return decompress(path)
    return vio.read(path, **options)


def _serve_vtk(request: dict) -> dict:
    # VTK's readers: only for the files VTK reads
    from vtkmodules.vtkCommonCore import vtkOutputWindow, vtkStringOutputWindow
    from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline

    window = vtkStringOutputWindow()
    vtkOutputWindow.SetInstance(window)
    reader = _vtk_reader(request["recipe"], request["path"], request["options"])
    errors: list[str] = []
    reader.AddObserver("ErrorEvent", lambda *_: errors.append("error"))
    reader.UpdateInformation()
    steps = reader.GetOutputInformation(0).Get(vtkStreamingDemandDrivenPipeline.TIME_STEPS()) or [None]
    found: dict[str, Any] = {"n_points": 0, "crc": 0, "problem": "", "content": []}
    for i in frames_to_read(len(steps)):
        reader.UpdateTimeStep(steps[i]) if steps[i] is not None else reader.Update()
        output = reader.GetOutputDataObject(0)
        if output is not None:
            part = fingerprint_vtk(output)
            found = {"n_points": found["n_points"] + part["n_points"], "crc": zlib.crc32(str(part["crc"]).encode(),
                                                                                         found["crc"]), "problem": "",
                     "content": found["content"] + [part["content"]]}
    text = window.GetOutput() or ""
    if errors or "ERROR" in text or found["n_points"] == 0:
        return {"status": "error", "message": (text.strip().splitlines() or ["empty output"])[-1][:300],
                "named": True}
    return {"status": "ok", **found}


def worker(side: str) -> None:
    """A worker child: one JSON request per line on stdin, one JSON answer per line on the protocol descriptor
    (stdout is pointed at stderr so that readers printing cannot break the protocol)."""
    out = os.fdopen(os.dup(1), "w", buffering=1)
    os.dup2(2, 1)
    serve = _serve_volviz if side == "volviz" else _serve_vtk
    for line in sys.stdin:
        request = json.loads(line)
        t0 = time.perf_counter()
        try:
            answer = serve(request)
        except MemoryError:
            answer = {"status": "memory", "message": "MemoryError"}
        except Exception as exc:  # counted: the point of the bench
            answer = {"status": "exception", "message": f"{type(exc).__name__}: {exc}"[:300]}
        answer["seconds"] = time.perf_counter() - t0
        out.write(json.dumps(answer) + "\n")


class BenchWorker:
    """The parent's end of a worker child with a memory limit; a request that outlives ``seconds`` kills it."""

    def __init__(self, side: str, memory: int, seconds: float, folder: Path) -> None:
        self.side, self.memory, self.seconds = side, memory, seconds
        self.log = folder / f"{side}-stderr.log"
        self.proc: Optional[subprocess.Popen] = None
        self.restarts = 0

    def _start(self) -> subprocess.Popen:

        def limit() -> None:
            resource.setrlimit(resource.RLIMIT_AS, (self.memory, resource.RLIM_INFINITY))

        env = dict(os.environ, VOLVIZ_READ_SECONDS="10", PYTHONUNBUFFERED="1")
        with open(self.log, "ab") as err:
            return subprocess.Popen([sys.executable, "-m", "volviz.bench.robustness", "--worker", self.side],
                                    stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=err,
                                    preexec_fn=limit, env=env, text=True)

    def ask(self, request: dict) -> dict:
        if self.proc is None or self.proc.poll() is not None:
            self.proc = self._start()
            self.restarts += 1
        stdin, stdout = self.proc.stdin, self.proc.stdout
        assert stdin is not None and stdout is not None                 # _start pipes both
        os.truncate(self.log, 0)
        box: list[str] = []
        t0 = time.perf_counter()
        try:
            stdin.write(json.dumps(request) + "\n")
            stdin.flush()
        except OSError:
            pass
        reader = threading.Thread(target=lambda: box.append(stdout.readline()), daemon=True)
        reader.start()
        reader.join(self.seconds)
        elapsed = time.perf_counter() - t0
        if reader.is_alive():
            self.kill()
            reader.join()
            return {"status": "hang", "seconds": elapsed, "message": f"no answer within {self.seconds:.0f} s"}
        if box and box[0]:
            return json.loads(box[0])
        code = self.proc.wait()
        tail = self.log.read_bytes()[-4000:].decode("utf-8", "replace")
        self.proc = None
        if "bad_alloc" in tail or code == -signal.SIGKILL or "MemoryError" in tail:
            return {"status": "memory", "seconds": elapsed, "message": f"exit {code}: out of memory"}
        name = signal.Signals(-code).name if code < 0 else f"exit {code}"
        return {"status": "crash", "seconds": elapsed, "message": f"{name}: {tail.strip()[-200:]}"}

    def kill(self) -> None:
        if self.proc is not None:
            self.proc.kill()
            self.proc.wait()
            self.proc = None

    def close(self) -> None:
        if self.proc is not None and self.proc.poll() is None:
            assert self.proc.stdin is not None                          # _start pipes it
            self.proc.stdin.close()
            self.proc.wait(timeout=30)
        self.proc = None


# -- the campaign ------------------------------------------------------------------------------------------------------
def prepare_folder(src: Source, base: Path, index: int) -> Path:
    """A folder holding the file to mutate's companions (symbolic links); for OpenFOAM a mirror of the case."""
    folder = base / f"s{index}"
    if folder.exists():
        return folder
    if src.mirror is not None:
        _mirror(src.mirror, folder)
        return folder
    if src.fmt == "openfoam":
        _mirror(next(p for p in src.path.parents if (p / "case.foam").exists()), folder)
        src.target = "case.foam"
        src.links = {}
        return folder
    folder.mkdir(parents=True)
    for name, path in src.links.items():
        (folder / name).symlink_to(path)
    return folder


def _mirror(root: Path, folder: Path) -> None:
    """Every file under ``root`` as a symbolic link at the same place under ``folder``."""
    for f in root.rglob("*"):
        if f.is_file():
            (folder / f.relative_to(root)).parent.mkdir(parents=True, exist_ok=True)
            (folder / f.relative_to(root)).symlink_to(f)


def mutated_path(src: Source, folder: Path) -> Path:
    if src.mirror is not None:
        return folder / src.path.relative_to(src.mirror)
    if src.fmt == "openfoam":
        case = next(p for p in src.path.parents if (p / "case.foam").exists())
        return folder / src.path.relative_to(case)
    return folder / src.path.name


#: formats whose files carry no count of what they hold: a text table cut at (or within) its last rows is a table of
#: fewer rows, which no reader can tell apart from one written that way
UNSIZED = ("csv", "xyz")


def _judge(answer: dict, original: Optional[dict], mutation: Mutation, fmt: str = "") -> str:
    """The outcome of one read: clean, exception, crash, hang, memory, garbage, warned or accepted (for the
    ``UNSIZED`` formats also a truncated file read as fewer points: it cannot be told apart)."""
    status = answer["status"]
    if status == "error":
        return "clean" if answer.get("named", True) else "exception"
    if status != "ok":
        return status
    if answer.get("problem"):
        return "garbage"
    if answer.get("warned"):
        return "warned"  # read, with a ReadWarning naming the file and what is doubtful
    if original is None:
        return "accepted"
    same = (answer["n_points"], answer["crc"]) == (original["n_points"], original["crc"])
    if mutation.kind == "truncate" and fmt in UNSIZED and 0 < answer["n_points"] <= original["n_points"]:
        return "accepted"
    if mutation.kind == "truncate" and not same:
        return "garbage"  # the file lost bytes and the reader made up the rest
    if answer["n_points"] != original["n_points"]:
        return "garbage"  # a changed size was accepted though the data did not change with it
    return "accepted"


OUTCOMES = ("clean", "exception", "crash", "hang", "memory", "garbage", "valid", "warned", "accepted")


def run(data: Path, total: int, seed: int, formats: list[str] | None, minutes: float = 0.0,
        progress: bool = True, record: Optional[Path] = None) -> dict:
    """The campaign: ``total`` cases (fewer when ``minutes`` > 0 runs out first), counted per format and side;
    with ``record``, one JSON line per case there (``volviz.bench.robustness_replay``: what each case changed,
    enough to rebuild it with ``--replay``)."""
    made_folder = Path(tempfile.mkdtemp(prefix="volviz-bench-made-"))
    shared = sources(data)
    srcs = [s for s in shared + made_sources(made_folder, formats) if not formats or s.fmt in formats]
    origin = {id(s): "data" for s in shared}
    recorder = Recorder(record)
    todo = cases(srcs, total, seed)
    t_start = time.perf_counter()
    stats: dict[tuple[str, str], Counter] = defaultdict(Counter)
    slowest: dict[tuple[str, str], float] = defaultdict(float)
    refusal_times: dict[tuple[str, str], list[float]] = defaultdict(list)
    slowest_case: dict[tuple[str, str], dict] = {}
    examples: dict[tuple[str, str, str], list[dict]] = defaultdict(list)
    contained: Counter = Counter()
    with tempfile.TemporaryDirectory(prefix="volviz-bench-robustness-") as tmp:
        base = Path(tmp)
        sides = {"volviz": BenchWorker("volviz", 6 << 30, 40.0, base),
                 "vtk": BenchWorker("vtk", 3 << 30, VTK_SECONDS, base)}
        index = {id(s): i for i, s in enumerate(srcs)}
        originals: dict[tuple[int, str], Optional[dict]] = {}
        done = 0
        addresses: dict[int, list[int]] = {}
        slow_cases: list[tuple[Source, tuple, float]] = []
        for n, (src, recipe) in enumerate(todo):
            if minutes > 0 and time.perf_counter() - t_start > 60 * minutes:
                break
            done = n + 1
            raw = src.path.read_bytes()
            if src.layout == "hdf5" and id(src) not in addresses:
                addresses[id(src)] = hdf5_object_addresses(src.path)
            mutation = make_mutation(src, raw, recipe, addresses.get(id(src)))
            folder = prepare_folder(src, base, index[id(src)])
            target = mutated_path(src, folder)
            requests: dict[str, dict[str, Any]] = {
                "volviz": {"path": str(folder / src.target), "options": src.options},
                "vtk": {"path": str(folder / src.target), "options": src.options, "recipe": src.vtk}}
            active = [s for s in sides if s == "volviz" or src.vtk]
            for side in active:
                if (index[id(src)], side) not in originals:
                    place(target, raw)
                    first = sides[side].ask(requests[side])
                    originals[(index[id(src)], side)] = first if first["status"] == "ok" else None
            place(target, mutation.data if mutation.data is not None else raw)
            if mutation.edit is not None:
                try:
                    mutation.edit(target)
                except Exception as exc:  # h5py refused the edit: the case is a plain copy
                    mutation = Mutation("hdf5-field", f"edit failed ({exc})", None)
            case = case_record(n, seed, src, origin.get(id(src), "made"), recipe, mutation, raw,
                               target.read_bytes() if mutation.data is None else mutation.data)
            answers: dict[str, dict] = {}
            threads = [threading.Thread(target=lambda s=s: answers.__setitem__(s, sides[s].ask(requests[s])))
                       for s in active]
            for t in threads:
                t.start()
            for t in threads:
                t.join()
            outcomes = {side: _judge(answer, originals[(index[id(src)], side)], mutation, src.fmt)
                        for side, answer in answers.items()}
            if "garbage" in outcomes.values() and valid_as_damaged(mutation.kind, answers):
                outcomes = {side: "valid" for side in outcomes}
            for side, answer in answers.items():
                outcome = outcomes[side]
                key = (src.fmt, side)
                stats[key][outcome] += 1
                stats[key]["cases"] += 1
                if outcome == "clean":
                    if answer["seconds"] > slowest[key]:
                        slowest_case[key] = {"file": src.name, "mutation": mutation.kind,
                                             "detail": mutation.detail[:160], "message": answer["message"][:240]}
                    slowest[key] = max(slowest[key], answer["seconds"])
                    refusal_times[key].append(answer["seconds"])
                    stats[key]["slow"] += answer["seconds"] >= REFUSAL_TARGET_S
                    if side == "volviz" and answer["seconds"] >= REFUSAL_TARGET_S:
                        slow_cases.append((src, recipe, answer["seconds"]))
                    if side == "volviz" and re.search(r"crashed|ran out of memory|time limit", answer["message"]):
                        contained[src.fmt] += 1
                if outcome not in ("clean", "accepted") and len(examples[(src.fmt, side, outcome)]) < 5:
                    examples[(src.fmt, side, outcome)].append(
                        {"file": src.name, "mutation": mutation.kind, "detail": mutation.detail[:160],
                         "message": (answer.get("message") or answer.get("warned", ""))[:240]})
            recorder.write({**case, "outcome": outcomes,
                            "message": {side: (a.get("message") or a.get("warned") or "")[:240]
                                        for side, a in answers.items()}})
            if progress and (n + 1) % 200 == 0:
                rate = (n + 1) / (time.perf_counter() - t_start)
                print(f"{n + 1}/{len(todo)} cases, {rate:.1f}/s", file=sys.stderr, flush=True)
        retimed = _retime(slow_cases, sides["volviz"], base, index, addresses)
        for w in sides.values():
            w.close()
    recorder.close()
    shutil.rmtree(made_folder, ignore_errors=True)
    return {"retimed": retimed, "stats": {f"{k[0]}|{k[1]}": dict(v) for k, v in stats.items()},
            "slowest": {f"{k[0]}|{k[1]}": v for k, v in slowest.items()}, "contained": dict(contained),
            "p99": {f"{k[0]}|{k[1]}": float(sorted(v)[min(len(v) - 1, int(0.99 * len(v)))])
                    for k, v in refusal_times.items()},
            "slowest_case": {f"{k[0]}|{k[1]}": v for k, v in slowest_case.items()},
            "examples": {"|".join(k): v for k, v in examples.items()}, "cases": done, "planned": len(todo),
            "seed": seed,
            "seconds": time.perf_counter() - t_start, "files": len(srcs),
            "restarts": {s: w.restarts for s, w in sides.items()}}


RETIME_REPS = 3


def _retime(slow: list[tuple[Source, tuple, float]], worker: "BenchWorker", base: Path, index: dict[int, int],
            addresses: dict[int, list[int]]) -> list[dict]:
    """Each volviz refusal that took 1 s or more, read again ``RETIME_REPS`` times after the campaign: the median
    tells a slow check from a moment of load on the shared machine (or a reader child that was starting after a
    crash) when the single timing was taken."""
    out = []
    for src, recipe, first in slow:
        folder = prepare_folder(src, base, index[id(src)])
        target = mutated_path(src, folder)
        data = src.path.read_bytes()
        mutation = make_mutation(src, data, recipe, addresses.get(id(src)))
        times = []
        for _ in range(RETIME_REPS):
            place(target, mutation.data if mutation.data is not None else data)
            if mutation.edit is not None:
                mutation.edit(target)
            answer = worker.ask({"path": str(folder / src.target), "options": src.options})
            if answer["status"] == "error":
                times.append(answer["seconds"])
        place(target, data)
        times.sort()
        out.append({"format": src.fmt, "file": src.name, "mutation": mutation.kind, "detail": mutation.detail[:160],
                    "first_s": first, "median_s": times[len(times) // 2] if times else None})
    return out


def place(target: Path, data: bytes) -> None:
    """Write the case's bytes as a new file at ``target`` (replacing the symbolic link of a mirrored case): a reader
    child that still holds the previous case open (an HDF5 file, locked) keeps that file, and h5py can edit this
    one (the retiming after a campaign stopped on "unable to lock file" editing it in place)."""
    target.unlink(missing_ok=True)
    target.write_bytes(data)


# -- the report --------------------------------------------------------------------------------------------------------
def _targets(result: dict) -> list[str]:
    volviz = [v for k, v in result["stats"].items() if k.endswith("|volviz")]
    total = sum(v.get("cases", 0) for v in volviz)
    bad = {o: sum(v.get(o, 0) for v in volviz) for o in ("crash", "hang", "memory", "exception", "garbage", "valid")}
    slow = max((v for k, v in result["slowest"].items() if k.endswith("|volviz")), default=0.0)
    n_slow = sum(v.get("slow", 0) for v in volviz)
    retimed = [r["median_s"] for r in result.get("retimed", []) if r["median_s"] is not None]
    slowest_median = max(retimed, default=0.0)
    ok = lambda flag: "met" if flag else "NOT met"  # noqa: E731
    return [
        f"- cases: {total} (target at least 10,000) — {ok(total >= 10000)}",
        f"- crashes, hangs, memory blow-ups of the volviz process: {bad['crash']}, {bad['hang']}, {bad['memory']} "
        f"— {ok(bad['crash'] + bad['hang'] + bad['memory'] == 0)}",
        f"- exceptions other than ReadError (or a ReadError not naming the file): {bad['exception']} — "
        f"{ok(bad['exception'] == 0)}",
        f"- silent garbage: {bad['garbage']} — {ok(bad['garbage'] == 0)} (besides, valid as damaged: {bad['valid']}, "
        "truncated files VTK's reader reads to the same content)",
        f"- slowest refusal: {slow:.2f} s, refusals of 1 s or more: {n_slow}; read again {RETIME_REPS} times "
        f"after the campaign, their slowest median is {slowest_median:.2f} s (target: every refusal under "
        f"{REFUSAL_TARGET_S:.0f} s, judged on the medians) — {ok(slowest_median < REFUSAL_TARGET_S)}",
    ]


def report(result: dict, command: str) -> str:
    load = os.getloadavg() if hasattr(os, "getloadavg") else (float("nan"),) * 3
    lines = [
        SECTION,
        "",
        f"Command: `{command}` — {time.strftime('%Y-%m-%d')}, {platform.machine()}, {os.cpu_count()} cores shared "
        f"with other work (load {load[0]:.1f}), Python {platform.python_version()}; {result['cases']} cases over "
        f"{result['files']} files in {result['seconds'] / 60:.1f} min (seed {result['seed']})" + (
            f"; stopped by `--minutes` after {result['cases']} of {result['planned']} planned cases." if
            result["cases"] < result["planned"] else "."),
        "",
        "Each case is one mutated copy of a file of `../shared/data`, or of a small file the run writes for each "
        "format the folder lacks (`volviz.bench.robustness_made`: MATLAB v5 plain and compressed, TIFF, NRRD raw "
        "and gzip, NIfTI, DICOM, cube, FITS, MRC, .npy, LAS, SEG-Y; `volviz.bench.robustness_formats`, several "
        "seeds each, every file of a seed of several files damaged in turn: XDMF, Tecplot, EnSight, AVS UCD, "
        "OME-Zarr, MINC, HDF5 arrays, CSV points, .xyz, BOV, PVD, LAZ, .vvz read as the app reads it) (bit flips; "
        "truncation at every header "
        "boundary; header fields set to 0, -1, 2^31-1, 2^63-1, NaN, non-numbers, as text or binary integers; XML "
        "attributes swapped, flipped and enlarged; HDF5 object headers damaged and VTKHDF counts set through h5py), "
        "read by `volviz.io.read` (isolated as by default) and by VTK's reader of the format, each side in a worker "
        "child with a memory limit (volviz 6 GiB, VTK 3 GiB) and a time limit (volviz 40 s, with "
        "`VOLVIZ_READ_SECONDS=10` for its own reader child; VTK 5 s). *clean*: volviz's `ReadError` naming the "
        "file, VTK's error message or empty output; *garbage*: a read that succeeds although the truncated file "
        "lost data, or with a grid size other than the original's, or with inconsistent arrays or non-finite "
        "spacing/origin; *valid*: valid as damaged, a truncated file that volviz and VTK's reader both read to "
        "the same content (points, bounds, every array's size, sum, minimum and maximum; "
        "`volviz.bench.robustness_agree`), a valid file of the format as it was cut, not counted as garbage; "
        "*warned*: a read that succeeds with a `ReadWarning` naming the file and what will be "
        "shown other than meant (e.g. a CF coordinate the reader takes for data); *accepted*: a read of the "
        "original's size (a flipped data bit cannot be told apart), and for CSV and .xyz tables, which carry no "
        "count, a truncated file read as the rows it still holds; "
        "*contained*: volviz refusals where its reader child crashed, ran out of memory or time (VTK's failure "
        "caught by the isolation, not by a header check).",
        "",
        "### Targets",
        "",
        *_targets(result),
        "",
        "### Per format: volviz | VTK",
        "",
        "| format | cases | clean | other exceptions | crashes | hangs | memory | garbage | valid | warned | "
        "accepted | slowest refusal | p99 refusal | contained |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    fmts = sorted({k.split("|")[0] for k in result["stats"]})
    for fmt in fmts:
        v = result["stats"].get(f"{fmt}|volviz", {})
        t = result["stats"].get(f"{fmt}|vtk")
        cell = lambda o: f"{v.get(o, 0)} \\| {t.get(o, 0) if t else '—'}"  # noqa: E731
        slow = f"{result['slowest'].get(f'{fmt}|volviz', 0):.2f} s \\| " + (
            f"{result['slowest'].get(f'{fmt}|vtk', 0):.2f} s" if t else "—")
        p99 = result.get("p99", {})
        tail = f"{p99.get(f'{fmt}|volviz', 0):.2f} s \\| " + (f"{p99.get(f'{fmt}|vtk', 0):.2f} s" if t else "—")
        lines.append(f"| {fmt} | {v.get('cases', 0)} | " + " | ".join(cell(o) for o in OUTCOMES) +
                     f" | {slow} | {tail} | {result['contained'].get(fmt, 0)} |")
    lines += ["", "The slowest volviz refusal of each format (time on the loaded machine, both sides reading at once):",
              ""]
    for key, item in sorted(result.get("slowest_case", {}).items()):
        if key.endswith("|volviz"):
            lines.append(f"- {key.split('|')[0]}: {result['slowest'][key]:.2f} s, `{item['file']}` {item['mutation']} "
                         f"({item['detail']}): {item['message']}".replace("\n", " "))
    if result.get("retimed"):
        lines += ["", f"The refusals of 1 s or more, each read again {RETIME_REPS} times after the campaign "
                      "(first time -> median):", ""]
        for r in result["retimed"]:
            median = "no refusal" if r["median_s"] is None else f"{r['median_s']:.3f} s"
            lines.append(f"- {r['format']}: {r['first_s']:.2f} s -> {median}, `{r['file']}` {r['mutation']} "
                         f"({r['detail']})")
    lines += ["", "— : VTK has no reader of the format (PVM, MATLAB, cube, FITS, .npy, LAS/LAZ, SEG-Y, OME-Zarr, "
                  "HDF5 arrays, CSV, BOV, PVD, .vvz). Examples of each failure (at most five per format, side and "
                  "kind):", ""]
    for key, items in sorted(result["examples"].items()):
        for item in items:
            lines.append(f"- {key.replace('|', ' / ')}: `{item['file']}` {item['mutation']} ({item['detail']}): "
                         f"{item['message']}".replace("\n", " "))
    return "\n".join(lines) + "\n"


def write_section(path: Path, text: str) -> None:
    """Replace (or append) the campaign's section of ``path``, keeping every other section."""
    old = path.read_text(encoding="utf-8") if path.exists() else ""
    start = old.find(SECTION + "\n")
    if start >= 0:
        rest = re.search(r"^## ", old[start + len(SECTION):], re.M)
        end = start + len(SECTION) + rest.start() if rest else len(old)
        new = old[:start] + text + ("\n" + old[end:] if rest else "")
    else:
        new = old.rstrip("\n") + "\n\n" + text
    path.write_text(new, encoding="utf-8")


def main(argv: list[str] | None = None) -> int:
    parser = UsageParser(prog="volviz bench robustness", description=__doc__.split("\n")[0])
    parser.add_argument("--data", metavar="DIR", type=Path, default=DEFAULT_DATA,
                        help="the shared data folder (default: $VOLVIZ_DATA or ../shared/data)")
    parser.add_argument("--cases", type=int_in(1, 10_000_000), default=10000, help="mutated files (default 10000)")
    parser.add_argument("--seed", type=int_in(0, 2**31), default=1)
    parser.add_argument("--formats", nargs="+", metavar="FORMAT", help="only these formats (pvm slc pnm metaimage "
                        "dem plot3d vtk-legacy vti vtu vtkhdf jpeg exodus cgns netcdf openfoam raw tecplot fluent-cff "
                        "xdmf; written for the run: matlab matlab-z tiff nrrd nrrd-gzip nifti dicom cube fits mrc npy "
                        "las segy xdmf tecplot ensight avs-ucd ome-zarr minc hdf5 csv xyz bov pvd laz vvz)")
    parser.add_argument("--minutes", type=float, default=0.0,
                        help="stop starting new cases after this many minutes (0: no limit); the report says so")
    parser.add_argument("--out", metavar="FILE", type=Path, default=REPORT,
                        help="the markdown file whose section is written (default docs/reliability.md)")
    parser.add_argument("--json", metavar="OUT", help="also write the raw results as JSON")
    parser.add_argument("--record", metavar="FILE", type=Path,
                        help="one JSON line per case: its seed file, recipe, the bytes and bits it changed, the "
                             "damaged file's SHA-256 and both outcomes (default: the --out file with .cases.jsonl)")
    parser.add_argument("--replay", metavar="CASE", type=int_in(0),
                        help="rebuild case CASE of --record (the damaged file among its seed's other files, checked "
                             "against the recorded SHA-256) and read it as the campaign does; no campaign")
    parser.add_argument("--into", metavar="DIR", type=Path, help="where --replay rebuilds the case (default: a new "
                        "temporary folder)")
    args = parser.parse_args([] if argv is None else argv)
    if not args.data.is_dir():
        parser.error(f"--data {args.data} is not a folder (set VOLVIZ_DATA)")
    record = args.record or args.out.with_suffix(".cases.jsonl")
    if args.replay is not None:
        if args.record is None:
            parser.error("--replay needs --record FILE, the campaign's record of its cases")
        try:
            print("\n".join(replay(args.record, args.replay, args.data.resolve(), args.into)))
        except ReplayError as exc:
            print(f"volviz bench robustness: {exc}", file=sys.stderr)
            return 1
        return 0
    result = run(args.data.resolve(), args.cases, args.seed, args.formats, args.minutes, record=record)
    command = " ".join(["volviz bench robustness", *(shlex.quote(a) for a in argv or [])])
    write_section(args.out, report(result, command))
    if args.json:
        Path(args.json).write_text(json.dumps(result, indent=1), encoding="utf-8")
    print("\n".join([f"wrote {args.out} and the record of every case, {record}", *_targets(result)]))
    return 0



# ------------------------------------------------------------------------------------ replay of a recorded case
def _source(item: dict[str, Any], data: Path, made: Path) -> Source:
    if item["origin"] == "made":
        candidates = made_sources(made, [item["format"]])
    else:
        candidates = [s for s in sources(data) if s.fmt == item["format"]]
    src = next((s for s in candidates if s.name == item["file"]), None)
    if src is None:
        where = "the seeds written for the run" if item["origin"] == "made" else str(data)
        raise ReplayError(f"case {item['case']}: its seed file {item['file']} is not among {where}")
    held = sha256(src.path.read_bytes())
    if held != item["source_sha256"]:
        raise ReplayError(f"case {item['case']}: the seed file {src.path} is not the recorded one "
                          f"(SHA-256 {held[:12]}..., recorded {item['source_sha256'][:12]}...)")
    return src


def rebuild(item: dict[str, Any], data: Path, into: Path) -> tuple[Path, Path, Source]:
    """Rebuild the damaged file of a recorded case under ``into`` (the seeds a run writes under ``into/made``, the
    case among its seed's other files under ``into/s<case>``); returns the damaged file, the file to open and the
    source. Raises ``ReplayError`` when the rebuilt bytes are not the recorded ones."""
    into.mkdir(parents=True, exist_ok=True)
    src = _source(item, data, into / "made")
    raw = src.path.read_bytes()
    addresses = hdf5_object_addresses(src.path) if src.layout == "hdf5" else None
    mutation = make_mutation(src, raw, decode_recipe(item["recipe"]), addresses)
    folder = prepare_folder(src, into, int(item["case"]))
    target = mutated_path(src, folder)
    place(target, mutation.data if mutation.data is not None else raw)
    if mutation.edit is not None:
        mutation.edit(target)
    made = sha256(target.read_bytes())
    if made != item["sha256"]:
        raise ReplayError(f"case {item['case']}: the rebuilt {target} is not the recorded file "
                          f"(SHA-256 {made[:12]}..., recorded {item['sha256'][:12]}...)")
    return target, folder / src.target, src


def replay(record: Path, case: int, data: Path, into: Optional[Path], read: bool = True) -> list[str]:
    """``volviz bench robustness --replay CASE``: rebuild the case, say where it is and, with ``read``, what
    volviz's reader makes of it now (as the campaign's volviz side reads it); a truncated file volviz reads is read
    by VTK's reader too (in the campaign's worker child), to say whether it is valid as damaged."""
    item = load(record, case)
    into = into if into is not None else Path(tempfile.mkdtemp(prefix=f"volviz-replay-{case}-"))
    target, opened, src = rebuild(item, data, into)
    lines = [f"case {case}: {item['format']} `{item['file']}` {item['kind']} ({item['detail']})",
             f"rebuilt {target} (SHA-256 {item['sha256'][:16]}... as recorded); open {opened}"]
    if item.get("outcome"):
        lines.append("recorded outcome: " + ", ".join(f"{k} {v}" for k, v in item["outcome"].items()))
    if read:
        answer = _serve_volviz({"path": str(opened), "options": src.options})
        now = answer["status"] if answer["status"] != "ok" else (
            "read, warned" if answer.get("warned") else "read")
        lines.append(f"volviz now: {now}: {answer.get('message') or answer.get('warned') or answer.get('problem')}"
                     .rstrip(": "))
        if answer["status"] == "ok" and src.vtk and item["kind"] == "truncate":
            side = BenchWorker("vtk", 3 << 30, VTK_SECONDS, into)
            try:
                theirs = side.ask({"path": str(opened), "options": src.options, "recipe": src.vtk})
            finally:
                side.close()
            same = valid_as_damaged(item["kind"], {"volviz": answer, "vtk": theirs})
            lines.append(f"VTK's reader now: {theirs['status']}" + (
                ", the same content: valid as damaged" if same else
                ", other content" if theirs["status"] == "ok" else f": {theirs.get('message', '')}"))
    return lines


if __name__ == "__main__":
    if sys.argv[1:2] == ["--worker"]:
        worker(sys.argv[2])
        sys.exit(0)
    sys.exit(main(sys.argv[1:]))
