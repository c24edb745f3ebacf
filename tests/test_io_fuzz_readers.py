"""Fuzz of every reader path on real files: mutated copies of small files from the shared data (bit flips,
truncation at header boundaries, header fields set to 0 / -1 / 2^31-1 / 2^63-1 / NaN / non-numbers, XML attributes
swapped, flipped and enlarged, HDF5 metadata damaged) go through ``volviz.io.read`` -- the VTK, HDF5 and netCDF
readers through the isolation layer, as by default. Property: the read returns a dataset whose arrays are consistent
(they survive the isolation codec's checks, finite spacing and origin), of the original's size, and identical to the
original when the file was truncated -- or raises ``ReadError`` naming the file; never another exception, never a
crash of this process. Also the writers (``volviz.io.atomic``, the .vvz container) under random targets.

The mutations are those of ``volviz bench robustness`` (the long campaign); here each file gets a few dozen, so the
whole file runs in well under a minute. ``VOLVIZ_FUZZ_EXAMPLES=N`` sets the examples per file for a deeper run.
"""
from __future__ import annotations

import os
import random
import stat
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import volviz.io as vio
from conftest import data_file
from volviz.bench import robustness as rb
from volviz.io.atomic import OutputPathError, atomic_write_bytes
from volviz.regular.container import Reader, VVZError, Writer

EXAMPLES = int(os.environ.get("VOLVIZ_FUZZ_EXAMPLES", "12"))
FUZZ = settings(max_examples=EXAMPLES, deadline=None, derandomize=True, database=None,
                suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow])

#: one small file per reader path (isolated ones: vtk-legacy, vti, vtu, vtkhdf, netcdf)
FILES = ["storm/Storm.pvm-t01", "volumes/neghip.slc", "yukon/Yukon.fogmap1.pgm", "terrain/SainteHelens.dem",
         "volumes/HeadMRVolume.mhd", "volumes/HeadMRVolume.raw", "bluntfin/bluntfinxyz.bin", "bluntfin/bluntfinq.bin",
         "volumes/ironProt.vtk", "volumes/hydrogen.vti", "ecosystem/notch_disp.vtu", "series/warping_spheres.vtkhdf",
         "ecosystem/sampleCurveGrid4.nc", "sky/clouds.jpeg"]


class Prepared:
    """A file's Source, its bytes, its folder of companions and what its unmutated read gives."""

    def __init__(self, relative: str, base: Path, index: int) -> None:
        path = data_file(relative)
        root = path.parents[1]
        self.src = next(s for s in rb.sources(path.parent) if s.path == path)
        self.src.root = root
        self.data = path.read_bytes()
        self.folder = rb.prepare_folder(self.src, base, index)
        self.target = rb.mutated_path(self.src, self.folder)
        self.addresses = rb.hdf5_object_addresses(path) if self.src.layout == "hdf5" else None
        rb.place(self.target, self.data)
        self.original = rb.fingerprint_volviz(self.read())
        assert self.original["problem"] == "" and self.original["n_points"] > 0, relative

    def read(self):
        options = dict(self.src.options)
        if "q" in options:
            options["q"] = self.folder / options["q"]
        if "dims" in options:
            options["dims"] = tuple(options["dims"])
        return vio.read(self.folder / self.src.target, **options)


@pytest.fixture(scope="module")
def prepared(tmp_path_factory) -> dict[str, Prepared]:
    base = tmp_path_factory.mktemp("fuzz-readers")
    return {}, base


def get(prepared, relative: str) -> Prepared:
    cache, base = prepared
    if relative not in cache:
        cache[relative] = Prepared(relative, base, len(cache))
    return cache[relative]


def check_case(p: Prepared, mutation: rb.Mutation) -> str:
    """Write the mutated file, read it; assert the property and return the outcome."""
    rb.place(p.target, mutation.data if mutation.data is not None else p.data)
    if mutation.edit is not None:
        mutation.edit(p.target)
    try:
        found = rb.fingerprint_volviz(p.read())  # a time series' frames are read here too
    except vio.ReadError as exc:
        assert str(exc).startswith(str(p.folder)), f"{mutation.detail}: {exc}"
        return "refused"
    assert found["problem"] == "", f"{mutation.detail}: {found['problem']}"
    assert found["n_points"] == p.original["n_points"], f"{mutation.detail}: size changed and was accepted"
    if mutation.kind == "truncate":
        assert found["crc"] == p.original["crc"], f"{mutation.detail}: a truncated file read with other data"
    return "read"


@pytest.mark.parametrize("relative", FILES)
@FUZZ
@given(seed=st.integers(0, 2**32 - 1), choice=st.integers(0, 63))
def test_mutated_real_file_reads_consistently_or_raises_read_error(prepared, relative, seed, choice):
    p = get(prepared, relative)
    kinds = rb.RANDOM_KINDS[p.src.layout]
    mutation = rb.random_mutation(p.src, p.data, random.Random(seed), p.addresses, kinds[choice % len(kinds)])
    check_case(p, mutation)


@pytest.mark.parametrize("relative", ["storm/Storm.pvm-t01", "volumes/HeadMRVolume.mhd", "volumes/ironProt.vtk",
                                      "yukon/Yukon.fogmap1.pgm"])
def test_every_header_boundary_and_field_value(prepared, relative):
    """The systematic cases of a text header: truncated after every line and word, every number set to each of
    0, -1, 2^31-1, 2^63-1, nan, a word, ... -- at most 120 of them, spread over the list."""
    p = get(prepared, relative)
    cases = rb.systematic(p.src, p.data)
    outcomes = [check_case(p, m) for m in cases[:: max(1, len(cases) // 120)]]
    assert outcomes.count("refused") > len(outcomes) // 2


def test_dem_resolution_that_collapses_the_profiles_is_refused(prepared):
    """Found by the campaign: one character deleted from the DEM's A record shifts the resolution to 3e19, which put
    all 327 profiles on one column (a 464 x 1 grid); now a ReadError."""
    p = get(prepared, "terrain/SainteHelens.dem")
    mutation = rb.Mutation("field", "a character deleted at byte 161", p.data[:160] + p.data[161:])
    assert check_case(p, mutation) == "refused"
    with pytest.raises(vio.ReadError, match="puts 327 profiles .* on 1 columns"):
        p.read()


# ---------------------------------------------------------------- writers under random targets

names = st.text(st.characters(blacklist_characters="/\0", blacklist_categories=("Cs",)), min_size=1, max_size=260) \
    .filter(lambda n: n not in (".", ".."))
targets = st.sampled_from(["absent", "file", "folder", "symlink", "dangling", "fifo", "no-parent"])


def make_target(folder: Path, name: str, kind: str) -> Path:
    """A target of the given kind named ``name`` in ``folder`` (OSError where the name is too long to exist)."""
    path = folder / name
    if kind == "no-parent":
        return folder / "missing" / name
    if kind == "file":
        path.write_bytes(b"old")
    elif kind == "folder":
        path.mkdir()
    elif kind in ("symlink", "dangling"):
        other = folder / "other"
        if kind == "symlink":
            other.write_bytes(b"keep")
        path.symlink_to(other)
    elif kind == "fifo":
        os.mkfifo(path)
    return path


def leftovers(folder: Path) -> list[str]:
    return [n for n in os.listdir(folder) if ".volviz-tmp-" in n or ".volviz-old-" in n]


def write_vvz(path: Path, payload: bytes) -> None:
    """A one-brick container whose metadata the reader accepts (``container.check_meta``): the payload as a raw
    n x 1 x 1 volume of bytes."""
    from volviz.regular.container import DTYPE_KINDS

    n = len(payload)
    meta = {"format": "volviz-vvz", "dims": [n, 1, 1], "dtype": "uint8", "kind": DTYPE_KINDS["uint8"],
            "original_bytes": n, "payload_bytes": n, "levels": 0, "tile": 1, "coder": "raw", "delta": 0}
    with Writer(path) as w:
        w.add(0, 0, 0, np.frombuffer(payload, np.uint8))
        w.close(meta)


@FUZZ
@given(name=names, kind=targets, payload=st.binary(min_size=1, max_size=4000),
       writer=st.sampled_from(["atomic", "vvz"]))
def test_writers_replace_only_regular_files(tmp_path_factory, name, kind, payload, writer):
    """Either the target is now a regular file holding what was written, or an OSError (OutputPathError for a
    target that is not a regular file) was raised and the target is as it was; no temporary is left behind."""
    folder = tmp_path_factory.mktemp("w")
    try:
        path = make_target(folder, name, kind)
    except OSError:  # a name the file system refuses (too long): the writers must refuse it too
        path = folder / name
    before = os.lstat(path).st_mode if os.path.lexists(path) else None
    try:
        if writer == "atomic":
            atomic_write_bytes(path, payload)
        else:
            write_vvz(path, payload)
    except OSError as exc:
        assert kind not in ("absent", "file") or len(name.encode()) > 200, f"{kind}: {exc}"
        if kind not in ("absent", "file", "no-parent"):
            assert isinstance(exc, OutputPathError) and str(path) in str(exc)
        after = os.lstat(path).st_mode if os.path.lexists(path) else None
        assert after == before
    else:
        assert kind in ("absent", "file") and stat.S_ISREG(os.lstat(path).st_mode)
        if writer == "atomic":
            assert path.read_bytes() == payload
        else:
            r = Reader(path)
            assert r.brick_ok(0) and bytes(r.payload[int(r.table["offset"][0]):][:len(payload)]) == payload
            r.close()
    if kind != "no-parent":
        assert leftovers(folder) == []


@FUZZ
@given(seed=st.integers(0, 2**32 - 1), payload=st.binary(min_size=1, max_size=2000))
def test_damaged_vvz_raises_only_vvz_error(tmp_path_factory, seed, payload):
    """A .vvz written here, then bit-flipped or truncated: opening it and checking its bricks gives VVZError
    (a ReadError naming the file) or a valid table."""
    folder = tmp_path_factory.mktemp("v")
    path = folder / "a.vvz"
    write_vvz(path, payload)
    data = path.read_bytes()
    rng = random.Random(seed)
    src = rb.Source("vvz", path, folder, path.name, layout="binary", endian="<", header_end=64)
    mutation = rng.choice([rb.flip_bits(data, rng, 64), rb.truncate(data, rng.choice(rb.boundaries(src, data))),
                           rb.set_field(src, data, rng)])
    path.write_bytes(mutation.data)
    try:
        r = Reader(path)
        [r.brick_ok(i) for i in range(len(r.table))]
        r.close()
    except VVZError as exc:
        assert str(path) in str(exc)
