"""Property tests: every header parser and reader, fed random bytes or random mutations of a valid file, raises
only volviz.io.ReadError (never another exception, never a hang or a huge allocation)."""
from __future__ import annotations

import os
import zlib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import volviz.io as vio
from volviz.io.dem import parse_dem_header
from volviz.io.metaimage import parse_mhd_header
from volviz.io.plot3d import detect_layout
from volviz.io.pnm import parse_pnm_header
from volviz.io.pvm import parse_pvm_header
from volviz.io.slc import parse_slc_header

# VOLVIZ_FUZZ_EXAMPLES raises the example count for a deeper run outside CI
FUZZ = settings(max_examples=int(os.environ.get("VOLVIZ_FUZZ_EXAMPLES", "120")), deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture,
                                                                          HealthCheck.too_slow])


# ---------------------------------------------------------------- valid seed files


def seed_pvm() -> bytes:
    return b"PVM3\n3 2 2\n0.5 1 2\n2\n" + np.arange(12, dtype=">u2").tobytes() + b"desc\0"


def seed_pgm() -> bytes:
    return b"P5\n# c\n4 3\n255\n" + bytes(range(12))


def seed_ppm_ascii() -> bytes:
    return b"P3\n2 2\n1000\n" + b" ".join(str(v).encode() for v in range(0, 1000, 84)) + b"\n"


def seed_slc() -> bytes:
    head = b"11111\n4 3 2 8\n1.0 1.0 2.0\n1 6 0 1\n2 1 X" + bytes(6)
    plane = b"\x05\x07\x83\x01\x02\x03\x04\x09\x00"  # 5 x 7, 3 literals, 4 x 9 = 12 voxels, end
    return head + b"9 X" + plane + b"9 X" + plane


def seed_mha() -> bytes:
    packed = zlib.compress(np.arange(24, dtype="<f4").tobytes())
    return (b"ObjectType = Image\nNDims = 3\nDimSize = 2 3 4\nElementSpacing = 1 1 2\nElementType = MET_FLOAT\n"
            b"CompressedData = True\nElementDataFile = LOCAL\n" + packed)


def seed_mhd_text() -> bytes:
    return b"NDims = 3\nDimSize = 2 2 2\nElementType = MET_SHORT\nElementByteOrderMSB = True\nElementDataFile = d.raw\n"


def dem_bytes(profiles: list[tuple[float, float, list[int]]], res=30.0) -> bytes:
    """A small USGS DEM: type A record (1024 bytes) + one type B record per (x, y, elevations) profile."""
    xs = [p[0] for p in profiles]
    ys = [p[1] for p in profiles]
    top = max(y + res * (len(p[2]) - 1) for _, y, p in zip(xs, ys, profiles))
    corners = [(min(xs), min(ys)), (min(xs), top), (max(xs), top), (max(xs), min(ys))]
    elev = [v for p in profiles for v in p[2]]
    a = "SYNTHETIC".ljust(144) + "%6d%6d%6d%6d" % (1, 1, 1, 10) + "%24.15E" % 0 * 15 + "%6d%6d%6d" % (2, 2, 4)
    a += "".join("%24.15E%24.15E" % c for c in corners) + "%24.15E%24.15E" % (min(elev), max(elev))
    a += "%24.15E" % 0 + "%6d" % 0 + "%12.6E%12.6E%12.6E" % (res, res, 1.0) + "%6d%6d" % (1, len(profiles))
    out = a.replace("E", "D").ljust(1024)
    for j, (x, y, values) in enumerate(profiles):
        b = "%6d%6d%6d%6d" % (1, j + 1, len(values), 1)
        b += ("%24.15E" * 5 % (x, y, 0.0, min(values), max(values))).replace("E", "D")
        b += "".join("%6d" % v for v in values)
        out += b.ljust(-(-len(b) // 1024) * 1024)
    return out.encode("ascii")


def seed_dem() -> bytes:
    return dem_bytes([(1000.0, 2030.0, [5, 6, 7]), (1030.0, 2000.0, [1, 2, 3, 4]), (1060.0, 2000.0, [9, 8])])


def seed_xyz(markers: bool = True) -> bytes:
    payload = np.arange(36, dtype=">f4").tobytes()
    dims = np.array([3, 2, 2], ">i4").tobytes()
    if not markers:
        return dims + payload
    m = lambda b: np.array([len(b)], ">i4").tobytes() + b + np.array([len(b)], ">i4").tobytes()  # noqa: E731
    return m(dims) + m(payload)


SEEDS = {"a.pvm": seed_pvm, "a.pgm": seed_pgm, "a.ppm": seed_ppm_ascii, "a.slc": seed_slc, "a.mha": seed_mha,
         "a.dem": seed_dem, "a.xyz": seed_xyz}


def test_seed_files_are_valid(tmp_path):
    """The mutations below start from files that read correctly."""
    for name, make in SEEDS.items():
        (tmp_path / name).write_bytes(make())
        assert vio.read(tmp_path / name).n_points > 0, name
    dem = vio.read(tmp_path / "a.dem")
    assert dem.data.shape == (4, 3) and dem.origin == (1000.0, 2000.0)
    south_up = dem.data[::-1]
    np.testing.assert_array_equal(south_up[:, 0], [1, 5, 6, 7])  # starts 30 m north; the gap holds the minimum
    np.testing.assert_array_equal(south_up[:, 1], [1, 2, 3, 4])
    np.testing.assert_array_equal(south_up[:, 2], [9, 8, 1, 1])
    slc = vio.read(tmp_path / "a.slc")
    assert slc.data[:, :, 0].ravel(order="F").tolist() == [7] * 5 + [1, 2, 3] + [9] * 4


def test_synthetic_dem_vtk_compatible_equals_vtk(tmp_path):
    """vtkDEMReader divides by (columns // 100) and dies of SIGFPE below 100 profiles: use 120 of them."""
    import vtk
    from vtkmodules.util.numpy_support import vtk_to_numpy

    rng = np.random.default_rng(3)
    profiles = [(500.0 + 30 * j, 900.0 + 30 * int(rng.integers(0, 3)), rng.integers(-50, 4000, size=int(n)).tolist())
                for j, n in enumerate(rng.integers(1, 6, size=120))]
    path = tmp_path / "s.dem"
    path.write_bytes(dem_bytes(profiles))
    r = vtk.vtkDEMReader()
    r.SetFileName(str(path))
    r.Update()
    nx, ny, _ = r.GetOutput().GetDimensions()
    theirs = vtk_to_numpy(r.GetOutput().GetPointData().GetScalars()).reshape(ny, nx)[::-1]
    np.testing.assert_array_equal(vio.read(path, vtk_compatible=True).data, theirs)


# ---------------------------------------------------------------- helpers


def only_read_errors(path: Path, data: bytes, **options) -> None:
    path.write_bytes(data)
    try:
        vio.read(path, **options)
    except vio.ReadError as exc:
        assert str(path) in str(exc)


def mutate(seed: bytes, draw_ops: list[tuple[int, int, bytes]], cut: int | None) -> bytes:
    data = bytearray(seed)
    for kind, pos, payload in draw_ops:
        if not data:
            break
        pos %= len(data) + 1
        if kind == 0:      # overwrite
            data[pos:pos + len(payload)] = payload
        elif kind == 1:    # insert
            data[pos:pos] = payload
        else:              # delete
            del data[pos:pos + len(payload) + 1]
    if cut is not None:
        data = data[: cut % (len(data) + 1)]
    return bytes(data)


ops = st.lists(st.tuples(st.integers(0, 2), st.integers(0, 4096),
                         st.one_of(st.binary(min_size=1, max_size=6),
                                   st.sampled_from([b"0", b"-1", b" ", b"\n", b"99999999999", b"X", b"1e308", b"nan",
                                                    b"#", b"=", b"\xff\xff\xff\x7f", b"\x00\x00\x00\x00"]))),
               max_size=4)
cuts = st.one_of(st.none(), st.integers(0, 4096))


@pytest.fixture(scope="module")
def fuzz_dir(tmp_path_factory) -> Path:
    d = tmp_path_factory.mktemp("fuzz")
    (d / "d.raw").write_bytes(bytes(16))
    return d


# ---------------------------------------------------------------- mutations of valid files, full readers


@pytest.mark.parametrize("name", sorted(SEEDS))
@FUZZ
@given(edits=ops, cut=cuts)
def test_mutated_files_raise_only_read_error(fuzz_dir, name, edits, cut):
    only_read_errors(fuzz_dir / name, mutate(SEEDS[name](), edits, cut))


@FUZZ
@given(edits=ops, cut=cuts)
def test_mutated_mhd_headers_raise_only_read_error(fuzz_dir, edits, cut):
    only_read_errors(fuzz_dir / "h.mhd", mutate(seed_mhd_text(), edits, cut))


@FUZZ
@given(edits=ops, cut=cuts, markers=st.booleans())
def test_mutated_plot3d_pairs_raise_only_read_error(fuzz_dir, edits, cut, markers):
    (fuzz_dir / "p.xyz").write_bytes(seed_xyz(markers))
    q = np.array([3, 2, 2], ">i4").tobytes() + np.ones(4 + 60, ">f4").tobytes()
    only_read_errors(fuzz_dir / "p.q", mutate(q, edits, cut))
    try:
        vio.read(fuzz_dir / "p.xyz", q=fuzz_dir / "p.q")
    except vio.ReadError:
        pass


# ---------------------------------------------------------------- random bytes, header parsers


prefixes = st.sampled_from([b"", b"PVM\n", b"PVM2\n", b"PVM3\n", b"DDS v3d", b"P2", b"P3 ", b"P5\n", b"P6\n#",
                            b"11111\n", b"NDims = ", b"ElementDataFile = LOCAL\n"])


@FUZZ
@given(prefix=prefixes, body=st.binary(max_size=300))
def test_header_parsers_on_random_bytes(prefix, body):
    data = prefix + body
    for parse in (parse_pvm_header, parse_pnm_header, parse_slc_header, parse_mhd_header, parse_dem_header):
        try:
            parse("fuzz.bin", data)
        except vio.ReadError as exc:
            assert exc.path == "fuzz.bin"
    for kind in ("xyz", "q"):
        try:
            detect_layout("fuzz.bin", kind, data, len(data) + 37)
        except vio.ReadError:
            pass


@FUZZ
@given(dims=st.lists(st.integers(-2**31, 2**31 - 1), min_size=3, max_size=4), pad=st.integers(0, 64),
       bo=st.sampled_from(["<", ">"]))
def test_plot3d_header_with_random_dimensions(fuzz_dir, dims, pad, bo):
    only_read_errors(fuzz_dir / "r.xyz", np.array(dims, bo + "i4").tobytes() + bytes(pad))


@FUZZ
@given(nums=st.lists(st.one_of(st.integers(-10, 10**12), st.floats(allow_nan=True, allow_infinity=True)),
                     min_size=3, max_size=12), sep=st.sampled_from([b" ", b"\n", b"\t"]))
def test_text_headers_with_random_numbers(fuzz_dir, nums, sep):
    text = sep.join(str(n).encode() for n in nums)
    only_read_errors(fuzz_dir / "n.pvm", b"PVM2\n" + text + b"\n" + bytes(40))
    only_read_errors(fuzz_dir / "n.pgm", b"P5\n" + text + b"\n" + bytes(40))
    only_read_errors(fuzz_dir / "n.slc", b"11111\n" + text + b" X" + bytes(40))
    only_read_errors(fuzz_dir / "n.mha", b"NDims = 3\nDimSize = " + text.replace(b"\n", b" ") +
                     b"\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n" + bytes(40))
