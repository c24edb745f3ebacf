"""VisIt's Brick of Values (``volviz.io.bov``): zonal and nodal bricks placed in their brick, byte order,
components, offsets, and headers or data files that do not fit."""
from __future__ import annotations

import random
import warnings

import numpy as np
import pytest
from conftest import read_mutations

import volviz.io as vio
from volviz.bench import robustness as rb
from volviz.io.errors import ReadError
from volviz.model import RegularVolume

VALUES = np.random.default_rng(0).normal(size=(6, 5, 4))          # [x, y, z]


def _brick(folder, header: str, data: bytes, name="brick.bov"):
    (folder / "brick.values").write_bytes(data)
    path = folder / name
    path.write_text(header)
    return path


HEADER = ("TIME: 2.5\nDATA_FILE: brick.values\nDATA_SIZE: 6 5 4\nDATA_FORMAT: FLOAT\nVARIABLE: density\n"
          "DATA_ENDIAN: LITTLE\nCENTERING: zonal\nBRICK_ORIGIN: -3 0 10\nBRICK_SIZE: 6 10 2\n")


def test_a_zonal_brick_is_placed_at_its_cell_centres(tmp_path):
    volume = vio.read(_brick(tmp_path, HEADER, VALUES.astype("<f4").tobytes(order="F")))
    assert isinstance(volume, RegularVolume) and volume.name == "density" and volume.dimensions == (6, 5, 4)
    np.testing.assert_array_equal(volume.data, VALUES.astype(np.float32))
    assert volume.spacing == (1.0, 2.0, 0.5) and volume.origin == (-2.5, 1.0, 10.25)
    nodal = HEADER.replace("zonal", "nodal").replace("LITTLE", "BIG").replace("FLOAT", "DOUBLE")
    volume = vio.read(_brick(tmp_path, nodal, VALUES.astype(">f8").tobytes(order="F")))
    np.testing.assert_array_equal(volume.data, VALUES)
    np.testing.assert_allclose(volume.spacing, (6 / 5, 10 / 4, 2 / 3))
    assert volume.origin == (-3.0, 0.0, 10.0)


def test_components_and_byte_offset(tmp_path):
    vectors = np.stack([VALUES, -VALUES, 2 * VALUES], axis=0)          # components fastest on disk
    header = HEADER + "DATA_COMPONENTS: 3\nBYTE_OFFSET: 16\n"
    volume = vio.read(_brick(tmp_path, header, bytes(16) + vectors.astype("<f4").tobytes(order="F")))
    assert volume.arrays["density"].shape == (6, 5, 4, 3)
    np.testing.assert_array_equal(volume.arrays["density"][..., 2], (2 * VALUES).astype(np.float32))


@pytest.mark.parametrize("edit, problem", [
    (lambda h: h.replace("6 5 4", "6 5 5"), "need 480 bytes .* the file holds 480|need 600 bytes"),
    (lambda h: h.replace("FLOAT", "QUAD"), "BOV DATA_FORMAT is not one of"),
    (lambda h: h.replace("brick.values", "gone.values"), "its data file gone.values is missing"),
    (lambda h: h.replace("DATA_SIZE: 6 5 4\n", ""), "is not a BOV header"),
    (lambda h: h.replace("BRICK_SIZE: 6 10 2", "BRICK_SIZE: 6 -10 2"), "BRICK_SIZE .* is not positive"),
])
def test_headers_that_do_not_fit_are_refused_naming_the_file(tmp_path, edit, problem):
    path = _brick(tmp_path, edit(HEADER), VALUES.astype("<f4").tobytes(order="F"))
    with pytest.raises(ReadError, match=problem):
        vio.read(path)


def test_mutated_headers_read_consistently_or_raise_read_error(tmp_path):
    path = _brick(tmp_path, HEADER, VALUES.astype("<f4").tobytes(order="F"))
    data = path.read_bytes()
    rng = random.Random("bov")
    mutations = [rb.flip_bits(data, rng, len(data)) for _ in range(24)]
    mutations += [rb.truncate(data, at) for at in sorted(rng.sample(range(1, len(data)), 12))]
    assert read_mutations(path, mutations, truncated_reads_same=True) >= 12


def test_a_header_cut_within_a_line_warns_naming_the_defaults_it_reads_with(tmp_path):
    """Issue #32 (the new-format campaign's BOV truncations): a header cut within ``VARIABLE: density`` lost
    ``DATA_ENDIAN: BIG`` and read every sample byte-swapped, without a word. A last line without its line end,
    with keys left to their defaults, is now a ReadWarning naming the line and those defaults; a header ending with
    its line end, or one that sets every key, says nothing."""
    big = HEADER.replace("LITTLE", "BIG")
    cut = big[:big.index("VARIABLE: dens") + len("VARIABLE: dens")]
    path = _brick(tmp_path, cut, VALUES.astype(">f4").tobytes(order="F"))
    with pytest.warns(vio.ReadWarning) as caught:
        vio.read(path, isolate=False)
    assert [str(w.message) for w in caught][0] == (
        f"{path}: its header's last line ('VARIABLE: dens') has no line end: if the header was cut short, keys are "
        "missing and read with their defaults (DATA_ENDIAN LITTLE, CENTERING zonal, BRICK_ORIGIN 0 0 0, BRICK_SIZE "
        "DATA_SIZE, DATA_COMPONENTS 1, BYTE_OFFSET 0)")
    # and the samples, big-endian floats read little-endian, look byte-swapped (the check of a header cut at a line end)
    assert len(caught) == 2 and "does not state DATA_ENDIAN" in str(caught[1].message)
    full = HEADER + "DATA_COMPONENTS: 1\nBYTE_OFFSET: 0"                # every key set, no final line end
    for header in (cut + "\n", full):
        with warnings.catch_warnings():
            warnings.simplefilter("error", vio.ReadWarning)
            vio.read(_brick(tmp_path, header, VALUES.astype("<f4").tobytes(order="F")), isolate=False)


@pytest.mark.parametrize("fmt, dtype, values", [
    ("SHORT", "i2", np.arange(120).reshape(6, 5, 4) * 37 % 251),          # the campaign's seed: small integers
    ("FLOAT", "f4", np.linspace(1.0, 5.0, 120).reshape(6, 5, 4)),                  # 22 % odd swapped, 0 % right
    ("INT", "i4", np.round(1e4 * np.sin(np.linspace(0, 3, 120))).reshape(6, 5, 4))])
def test_a_header_cut_at_a_line_end_that_lost_its_big_endian_line_warns(tmp_path, fmt, dtype, values):
    """Issue #32, the last silent acceptance of the campaign at seed 33 (case 1900): a header cut at a line end
    before ``DATA_ENDIAN: BIG`` is a valid header that reads big-endian samples little-endian (BOV's default). When
    the samples so read look byte-swapped (`volviz.io.raw.swapped_looks_right`: small integers whose low byte is
    always 0, a field far smoother swapped, floats of random exponents), a ReadWarning says so; the same samples
    stored little-endian, or a header that states its byte order, say nothing and read the values exactly."""
    header = HEADER.replace("FLOAT", fmt).replace("LITTLE", "BIG")
    cut = header[:header.index("DATA_ENDIAN")]
    with pytest.warns(vio.ReadWarning, match="does not state DATA_ENDIAN.*look byte-swapped"):
        vio.read(_brick(tmp_path, cut, values.astype(">" + dtype).tobytes(order="F")), isolate=False)
    for text, order in ((cut, "<"), (header, ">")):
        with warnings.catch_warnings():
            warnings.simplefilter("error", vio.ReadWarning)
            vol = vio.read(_brick(tmp_path, text, values.astype(order + dtype).tobytes(order="F")), isolate=False)
        assert np.array_equal(vol.data, values.astype(dtype))
