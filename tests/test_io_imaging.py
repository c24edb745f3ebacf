"""The imaging plugin (plugins/volviz-imaging) through ``volviz.io.read``: NIfTI (also gzip, .hdr/.img pairs, 4D, 5D
vectors), FreeSurfer MGH, NRRD (LPS space directions, gzip, detached headers, vector and time axes) and DICOM series,
each file written here by the format's own library (nibabel, pynrrd, pydicom) with a known voxel-to-world transform
that permutes and flips the axes. Every voxel volviz shows is checked against the file's voxel at the same RAS world
point (the placement and the value scaling both); and bad files."""
from __future__ import annotations

import gzip
import warnings
from pathlib import Path

import nibabel as nib
import nrrd
import numpy as np
import pydicom
import pytest
from pydicom.dataset import FileMetaDataset
from pydicom.uid import ExplicitVRLittleEndian, generate_uid

import volviz.io as vio
from volviz.io.errors import ChoiceWarning, ReadError, ReadWarning
from volviz.io.registry import spec_of
from volviz.model import RegularVolume, TimeSeries
from volviz.scene.opening import data_session
from volviz.scene.series import series_pattern

# voxel (i, j, k) -> RAS: i along -y (0.5 mm), j along +z (2 mm), k along -x (3 mm): a permutation with two flips
AFFINE = np.array([[0.0, 0.0, -3.0, 40.0],
                   [-0.5, 0.0, 0.0, 12.0],
                   [0.0, 2.0, 0.0, -7.0],
                   [0.0, 0.0, 0.0, 1.0]])
SHAPE = (6, 5, 4)


def _stored(shape=SHAPE, seed=0) -> np.ndarray:
    return np.random.default_rng(seed).integers(-300, 300, size=shape).astype(np.int16)


def _assert_placed(volume: RegularVolume, values: np.ndarray, affine: np.ndarray) -> None:
    """Every voxel of ``volume`` (origin + index x spacing in RAS) holds the file's voxel at that world point."""
    assert isinstance(volume, RegularVolume)
    assert sorted(volume.dimensions) == sorted(values.shape[:3])
    inverse = np.linalg.inv(affine)
    idx = np.indices(volume.dimensions).reshape(3, -1).T
    world = np.asarray(volume.origin) + idx * np.asarray(volume.spacing)
    voxel = world @ inverse[:3, :3].T + inverse[:3, 3]
    np.testing.assert_allclose(voxel, np.rint(voxel), atol=1e-6)  # every shown point is a voxel of the file
    ijk = np.rint(voxel).astype(int)
    expected = values[ijk[:, 0], ijk[:, 1], ijk[:, 2]]
    np.testing.assert_array_equal(volume.data.reshape(-1, *volume.data.shape[3:]), expected)


# -- NIfTI / Analyze / MGH ---------------------------------------------------------------------------------------------
def _nifti(path: Path, data: np.ndarray, affine=AFFINE, slope=None, inter=None, cls=nib.Nifti1Image) -> Path:
    img = cls(data, affine)
    if slope is not None:
        img.header.set_slope_inter(slope, inter)
    nib.save(img, str(path))
    return path


def test_nifti_voxels_are_placed_in_ras_through_the_files_scaling(tmp_path):
    stored = _stored()
    path = _nifti(tmp_path / "ct.nii", stored, slope=2.0, inter=-1024.0)
    volume = vio.read(path)
    assert spec_of(path).name == "nifti" and volume.name == "ct"
    assert volume.spacing == (3.0, 0.5, 2.0) and volume.origin == (31.0, 9.5, -7.0)
    _assert_placed(volume, stored * 2.0 - 1024.0, AFFINE)


@pytest.mark.parametrize("name", ["ct.nii.gz", "ct.hdr", "ct.img"])
def test_nifti_gzip_and_pairs_read_the_same_volume(tmp_path, name):
    stored = _stored(seed=1)
    target = tmp_path / name
    _nifti(target if name != "ct.img" else tmp_path / "ct.hdr", stored, cls=nib.Nifti1Pair if "nii" not in name
           else nib.Nifti1Image)
    _assert_placed(vio.read(target), stored, AFFINE)


def test_analyze_and_nifti2_and_mgh(tmp_path):
    stored = _stored(seed=2)
    for name, cls in (("a.hdr", nib.AnalyzeImage), ("b.nii", nib.Nifti2Image), ("c.mgz", nib.MGHImage)):
        affine = AFFINE if cls is not nib.AnalyzeImage else np.diag([2.0, 3.0, 4.0, 1.0])
        data = stored.astype(np.int32) if cls is nib.MGHImage else stored
        path = _nifti(tmp_path / name, data, affine, cls=cls)
        volume = vio.read(path)
        written = nib.load(str(path))  # Analyze keeps only the voxel sizes and its own origin convention
        _assert_placed(volume, stored, written.affine)


def test_nifti_4d_is_a_time_series_in_seconds_read_step_by_step(tmp_path):
    stored = _stored(SHAPE + (3,), seed=3)
    img = nib.Nifti1Image(stored, AFFINE)
    img.header.set_xyzt_units("mm", "msec")
    img.header["pixdim"][4] = 2500.0
    nib.save(img, str(tmp_path / "bold.nii.gz"))
    series = vio.read(tmp_path / "bold.nii.gz")
    assert isinstance(series, TimeSeries) and series.frames[1] is None  # later steps are read when shown
    np.testing.assert_allclose(series.times, [0.0, 2.5, 5.0])
    for t in range(3):
        _assert_placed(series.frame(t), stored[..., t], AFFINE)
    _assert_placed(vio.read(tmp_path / "bold.nii.gz", time_index=2), stored[..., 2], AFFINE)
    with pytest.raises(ReadError, match="time_index 3 is out of range: the file has 3"):
        vio.read(tmp_path / "bold.nii.gz", time_index=3)


def test_nifti_5d_vectors_are_one_array_of_components(tmp_path):
    stored = _stored(SHAPE + (1, 3), seed=4).astype(np.float32)
    path = _nifti(tmp_path / "warp.nii", stored)
    volume = vio.read(path)
    assert list(volume.arrays) == ["warp"] and volume.arrays["warp"].shape[3] == 3
    for c in range(3):
        shown = RegularVolume(volume.arrays["warp"][..., c], volume.spacing, volume.origin)
        _assert_placed(shown, stored[..., 0, c], AFFINE)
    np.testing.assert_allclose(volume.data, np.linalg.norm(volume.arrays["warp"], axis=-1), rtol=1e-6)


def test_an_oblique_scan_is_shown_on_its_nearest_axes_with_a_warning(tmp_path):
    angle = np.radians(10.0)
    rot = np.array([[np.cos(angle), -np.sin(angle), 0.0], [np.sin(angle), np.cos(angle), 0.0], [0.0, 0.0, 1.0]])
    affine = np.eye(4)
    affine[:3, :3] = rot @ np.diag([2.0, 2.0, 2.0])
    path = _nifti(tmp_path / "oblique.nii", _stored(seed=5), affine)
    with pytest.warns(ReadWarning, match=r"scanned obliquely \(10.0 degrees"):
        volume = vio.read(path, isolate=False)
    assert volume.spacing == pytest.approx((2.0, 2.0, 2.0))


def test_bad_nifti_files_say_what_is_wrong(tmp_path):
    good = _nifti(tmp_path / "good.nii", _stored())
    cut = tmp_path / "cut.nii"
    cut.write_bytes(good.read_bytes()[:500])
    with pytest.raises(ReadError, match=r"cut.nii.*needs 240 bytes .* holds only .*truncated"):
        vio.read(cut)
    header = bytearray(good.read_bytes()[:352])
    header[42:48] = np.array([30000, 30000, 30000], "<i2").tobytes()  # dim[1..3]: 54 GB of int16 claimed
    bomb = tmp_path / "bomb.nii.gz"
    bomb.write_bytes(gzip.compress(bytes(header) + b"\0" * 64))
    with pytest.raises(ReadError, match="more than its .* compressed bytes can inflate to"):
        vio.read(bomb)
    _nifti(tmp_path / "pair.hdr", _stored(), cls=nib.Nifti1Pair)
    (tmp_path / "pair.img").unlink()
    with pytest.raises(ReadError, match=r"pair.hdr: its data file pair.img is not beside it"):
        vio.read(tmp_path / "pair.hdr")
    junk = tmp_path / "junk.nii"
    junk.write_bytes(b"\x07" * 400)
    with pytest.raises(ReadError, match="junk.nii"):
        vio.read(junk)


# -- NRRD --------------------------------------------------------------------------------------------------------------
LPS = np.diag([-1.0, -1.0, 1.0, 1.0])


def _nrrd_header(affine_lps: np.ndarray, **extra) -> dict:
    return {"space": "left-posterior-superior", "space directions": affine_lps[:3, :3].T,
            "space origin": affine_lps[:3, 3], **extra}


@pytest.mark.parametrize("encoding", ["raw", "gzip"])
def test_nrrd_in_lps_lands_where_the_same_nifti_does(tmp_path, encoding):
    stored = _stored(seed=6)
    affine_lps = LPS @ AFFINE   # the same voxels at the same world points, written in LPS
    nrrd.write(str(tmp_path / "head.nrrd"), stored, _nrrd_header(affine_lps, encoding=encoding), index_order="F")
    volume = vio.read(tmp_path / "head.nrrd")
    _assert_placed(volume, stored, AFFINE)
    same = vio.read(_nifti(tmp_path / "head.nii", stored))
    assert (volume.origin, volume.spacing) == (same.origin, same.spacing)
    np.testing.assert_array_equal(volume.data, same.data)


def test_nrrd_detached_header_vector_and_time_axes(tmp_path):
    stored = _stored(seed=7)
    nrrd.write(str(tmp_path / "d.nhdr"), stored, _nrrd_header(LPS @ AFFINE), detached_header=True,
               index_order="F")
    _assert_placed(vio.read(tmp_path / "d.nhdr"), stored, AFFINE)

    vectors = _stored((3,) + SHAPE, seed=8).astype(np.float32)
    directions = np.vstack([np.full(3, np.nan), (LPS @ AFFINE)[:3, :3].T])
    origin = (LPS @ AFFINE)[:3, 3]
    nrrd.write(str(tmp_path / "v.nrrd"), vectors, {"space": "LPS", "space directions": directions,
                                                  "space origin": origin,
                                                  "kinds": ["vector", "domain", "domain", "domain"]},
               index_order="F")
    volume = vio.read(tmp_path / "v.nrrd")
    assert volume.arrays[volume.name.split(":")[0]].shape[3] == 3
    for c in range(3):
        arr = next(iter(volume.arrays.values()))[..., c]
        _assert_placed(RegularVolume(arr, volume.spacing, volume.origin), vectors[c], AFFINE)

    steps = _stored(SHAPE + (2,), seed=9)
    directions = np.vstack([(LPS @ AFFINE)[:3, :3].T, np.full(3, np.nan)])
    nrrd.write(str(tmp_path / "t.nrrd"), steps, {"space": "LPS", "space directions": directions,
                                                "space origin": origin,
                                                "kinds": ["domain", "domain", "domain", "time"]}, index_order="F")
    series = vio.read(tmp_path / "t.nrrd")
    assert isinstance(series, TimeSeries) and len(series) == 2
    for t in range(2):
        _assert_placed(series.frame(t), steps[..., t], AFFINE)


def test_bad_nrrd_files_say_what_is_wrong(tmp_path):
    nrrd.write(str(tmp_path / "d.nhdr"), _stored(), _nrrd_header(LPS @ AFFINE, encoding="raw"),
               detached_header=True, index_order="F")
    data = next(p for p in tmp_path.iterdir() if p.suffix != ".nhdr")
    data.write_bytes(data.read_bytes()[:100])
    with pytest.raises(ReadError, match=r"needs 240 bytes .* holds only 100 bytes"):
        vio.read(tmp_path / "d.nhdr")
    data.unlink()
    with pytest.raises(ReadError, match="its data file .* is not beside it"):
        vio.read(tmp_path / "d.nhdr")
    bad = tmp_path / "bad.nrrd"
    bad.write_bytes(b"NRRD0004\ntype: short\ndimension: 3\nsizes: 4 4\nencoding: raw\n\n" + b"\0" * 64)
    with pytest.raises(ReadError, match="bad.nrrd"):
        vio.read(bad)


# -- DICOM -------------------------------------------------------------------------------------------------------------
def dicom_series(folder: Path, values: np.ndarray, iop, origin, spacing, gap, names, series_uid=None,
                  slope=1.0, intercept=-1024.0, times=None, number=1, positions=None):
    """``values`` (slices, rows, cols) stored as CT slices of one series: slice s at origin + (s mod ``positions``)
    x gap x normal."""
    folder.mkdir(exist_ok=True)
    row, col = np.asarray(iop[:3], float), np.asarray(iop[3:], float)
    normal = np.cross(row, col)
    series_uid = series_uid or generate_uid()
    for s, name in enumerate(names):
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.2"
        meta.MediaStorageSOPInstanceUID = generate_uid()
        meta.TransferSyntaxUID = ExplicitVRLittleEndian
        ds = pydicom.Dataset()
        ds.file_meta = meta
        ds.SOPClassUID, ds.SOPInstanceUID = meta.MediaStorageSOPClassUID, meta.MediaStorageSOPInstanceUID
        ds.SeriesInstanceUID, ds.SeriesNumber, ds.SeriesDescription = series_uid, number, f"series {number}"
        ds.Modality = "CT"
        ds.InstanceNumber = len(names) - s          # the reverse of the stacking order
        ds.ImageOrientationPatient = [float(v) for v in iop]
        place = s % (positions or len(names))
        ds.ImagePositionPatient = [float(v) for v in np.asarray(origin) + place * gap * normal]
        ds.PixelSpacing = [float(spacing[0]), float(spacing[1])]
        ds.RescaleSlope, ds.RescaleIntercept = slope, intercept
        if times is not None:
            ds.TriggerTime = times[s]
        ds.Rows, ds.Columns = values.shape[1:]
        ds.SamplesPerPixel, ds.PhotometricInterpretation = 1, "MONOCHROME2"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 1
        ds.PixelData = values[s].astype("<i2").tobytes()
        ds.save_as(folder / name, enforce_file_format=True)
    return series_uid


def _dicom_affine_ras(iop, origin, spacing, gap) -> np.ndarray:
    """voxel (column, row, slice) -> RAS, from DICOM's definition (PS3.3 C.7.6.2.1.1) and LPS -> RAS."""
    row, col = np.asarray(iop[:3], float), np.asarray(iop[3:], float)
    affine = np.eye(4)
    affine[:3, 0], affine[:3, 1] = row * spacing[1], col * spacing[0]
    affine[:3, 2], affine[:3, 3] = np.cross(row, col) * gap, origin
    return LPS @ affine


SAGITTAL = (0.0, 1.0, 0.0, 0.0, 0.0, -1.0)   # along a row: +y (posterior); down a column: -z (inferior)


def test_a_dicom_series_is_stacked_in_patient_space_in_hounsfield_units(tmp_path):
    stored = _stored((5, 6, 4), seed=10)      # 5 slices of 6 rows x 4 columns
    names = [f"IM{n:04d}.dcm" for n in (3, 1, 4, 0, 2)]  # file names in no order
    dicom_series(tmp_path / "ct", stored, SAGITTAL, (10.0, -20.0, 30.0), (0.7, 0.6), 2.5, names)
    expected = np.transpose(stored, (2, 1, 0)) * 1.0 - 1024.0   # (column, row, slice)
    affine = _dicom_affine_ras(SAGITTAL, (10.0, -20.0, 30.0), (0.7, 0.6), 2.5)
    with warnings.catch_warnings():  # nibabel's DICOM wrappers call themselves experimental; their affine is not
        warnings.simplefilter("ignore")
        from nibabel.nicom.dicomwrappers import wrapper_from_file

        nib_lps = wrapper_from_file(str(tmp_path / "ct" / names[0])).affine      # voxel (row, column) -> LPS
    in_plane = LPS @ affine                                        # this test's own reading of PS3.3 C.7.6.2.1.1
    np.testing.assert_allclose(in_plane[:3, [1, 0, 3]], nib_lps[:3, [0, 1, 3]], atol=1e-9)
    for target in (tmp_path / "ct", tmp_path / "ct" / names[2]):  # the folder, or any one slice of it
        volume = vio.read(target)
        assert volume.name == "CT (HU)" and volume.dimensions == (5, 4, 6)
        _assert_placed(volume, expected, affine)
    assert series_pattern(tmp_path / "ct" / names[2]) is None      # numbered slices are not a time series
    assert data_session(tmp_path / "ct" / names[2]).datasets[0].path.endswith(names[2])


def test_a_dicom_folder_of_files_without_extension_and_with_two_series(tmp_path):
    folder = tmp_path / "study"
    small, large = _stored((2, 4, 4), seed=11), _stored((3, 4, 4), seed=12)
    axial = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    dicom_series(folder, small, axial, (0, 0, 0), (1, 1), 1.0, ["1", "2"], number=1)
    uid = dicom_series(folder, large, axial, (0, 0, 0), (1, 1), 1.0, ["3", "4", "5"], number=2)
    assert spec_of(folder).name == "dicom"
    with pytest.warns(ReadWarning, match="holds 2 series; showing the one with the most files, 2 'series 2' "
                                         "\\(3 files") as caught:
        volume = vio.read(folder, isolate=False)
    _assert_placed(volume, np.transpose(large, (2, 1, 0)) - 1024.0, _dicom_affine_ras(axial, (0, 0, 0), (1, 1), 1))
    # the choices as data, for the app's chooser, also through the isolated reader; the series UIDs pick them
    for isolate in (False, True):
        with pytest.warns(ChoiceWarning) as caught:
            vio.read(folder, isolate=isolate)
        choice = next(w.message for w in caught if isinstance(w.message, ChoiceWarning))
        assert choice.option == "series" and choice.chosen == uid and choice.choices[0] == uid
        assert len(choice.choices) == 2 and choice.labels[1].startswith("1 'series 1' (2 files")
    with pytest.warns(ChoiceWarning, match="showing the one as asked, 1 'series 1'"):
        assert vio.read(folder, series=choice.choices[1]).dimensions == (4, 4, 2)
    assert vio.read(folder, series="1").dimensions == (4, 4, 2)
    assert vio.read(folder, series=uid).dimensions == (4, 4, 3)
    with pytest.raises(ReadError, match="no series 'nope'; the series here are: 1 'series 1' \\(2 files"):
        vio.read(folder, series="nope")


def test_a_dicom_series_repeating_each_position_is_a_time_series(tmp_path):
    stored = _stored((3, 4, 4), seed=13)
    phases = np.concatenate([stored, stored + 100])
    axial = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    names = [f"f{n}.dcm" for n in range(6)]
    dicom_series(tmp_path / "cine", phases, axial, (0, 0, 0), (1, 1), 2.0, names,
                  times=[0.0, 0.0, 0.0, 40.0, 40.0, 40.0], positions=3)
    series = vio.read(tmp_path / "cine")
    assert isinstance(series, TimeSeries) and list(series.times) == [0.0, 40.0]
    affine = _dicom_affine_ras(axial, (0, 0, 0), (1, 1), 2.0)
    _assert_placed(series.frame(1), np.transpose(stored + 100, (2, 1, 0)) - 1024.0, affine)


def test_uneven_dicom_slices_are_reported_and_bad_ones_named(tmp_path):
    axial = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0)
    folder = tmp_path / "uneven"
    dicom_series(folder, _stored((3, 4, 4), seed=14), axial, (0, 0, 0), (1, 1), 1.0, ["a.dcm", "b.dcm", "c.dcm"])
    moved = pydicom.dcmread(folder / "c.dcm")
    moved.ImagePositionPatient = [0.0, 0.0, 5.0]
    moved.save_as(folder / "c.dcm")
    with pytest.warns(ReadWarning, match="not evenly spaced \\(gaps 1 to 4 mm\\)"):
        vio.read(folder, isolate=False)
    cut = pydicom.dcmread(folder / "b.dcm")
    cut.PixelData = cut.PixelData[:10]
    cut.save_as(folder / "b.dcm")
    with pytest.raises(ReadError, match=r"b.dcm: its pixel data \(Explicit VR Little Endian\) could not be decoded"):
        vio.read(folder)
    empty = tmp_path / "empty"
    empty.mkdir()
    (empty / "notes.dcm").write_text("not dicom")
    with pytest.raises(ReadError, match="holds no DICOM image"):
        vio.read(empty)


def test_imaging_files_render_legibly_on_first_open(tmp_path):
    """A NIfTI head opens with the default visual: an image that is not the bare background."""
    from volviz.render.export import render_session

    z, y, x = np.mgrid[-1:1:24j, -1:1:28j, -1:1:20j]
    ball = (np.sqrt(x * x + y * y + z * z) < 0.8) * 800.0 + 40.0
    path = _nifti(tmp_path / "ball.nii.gz", ball.astype(np.int16), np.diag([1.0, 1.2, 0.9, 1.0]))
    with warnings.catch_warnings():
        warnings.simplefilter("error", ReadWarning)
        img = np.asarray(render_session(data_session(path), None, (160, 120)))
    background = img[0, 0].astype(int)
    changed = np.abs(img[..., :3].astype(int) - background[:3]).max(axis=-1) > 24
    assert 0.1 < changed.mean() < 0.9


# -- malformed files: mutated copies read consistently or raise ReadError ----------------------------------------------
def _fuzz_files(folder: Path) -> dict[str, Path]:
    stored = _stored(seed=20)
    files = {"nii": _nifti(folder / "f.nii", stored, slope=2.0, inter=1.0),
             "nii.gz": _nifti(folder / "f.nii.gz", stored)}
    nrrd.write(str(folder / "f.nrrd"), stored, _nrrd_header(LPS @ AFFINE, encoding="raw"), index_order="F")
    nrrd.write(str(folder / "g.nrrd"), stored, _nrrd_header(LPS @ AFFINE, encoding="gzip"), index_order="F")
    files.update({"nrrd": folder / "f.nrrd", "nrrd-gzip": folder / "g.nrrd"})
    dicom_series(folder / "dcm", _stored((1, 6, 5), seed=21), (1.0, 0.0, 0.0, 0.0, 1.0, 0.0), (0, 0, 0), (1, 1),
                 1.0, ["one.dcm"])
    files["dcm"] = folder / "dcm" / "one.dcm"
    return files


@pytest.mark.parametrize("kind", ["nii", "nii.gz", "nrrd", "nrrd-gzip", "dcm"])
def test_mutated_imaging_files_read_consistently_or_raise_read_error(tmp_path, kind):
    """Bit flips (mostly in the header: its first 400 bytes) and truncations at 16 places of each format, through
    the isolated reader: the same grid size, finite spacing and origin -- or a ReadError naming the file; a truncated
    file is never read as a volume."""
    import random

    from volviz.bench import robustness as rb

    from conftest import read_mutations

    path = _fuzz_files(tmp_path)[kind]
    data = path.read_bytes()
    rng = random.Random(kind)
    mutations = [rb.flip_bits(data, rng, min(400, len(data))) for _ in range(16)]
    mutations += [rb.truncate(data, at) for at in sorted(rng.sample(range(1, len(data)), 16))]
    assert read_mutations(path, mutations, truncated_reads_same=False) >= 16  # every truncation at least


# -- MRC / CCP4 --------------------------------------------------------------------------------------------------------
def test_an_mrc_map_in_its_axis_order_is_laid_out_x_y_z_in_angstrom(tmp_path):
    import mrcfile

    sections = _stored((4, 5, 6), seed=30).astype(np.float32)        # (sections, rows, columns)
    with mrcfile.new(tmp_path / "map.mrc") as mrc:
        mrc.set_data(sections)
        mrc.voxel_size = (1.5, 2.0, 2.5)
        mrc.header.origin = (10.0, 20.0, 30.0)
    volume = vio.read(tmp_path / "map.mrc")
    assert volume.name == "density" and volume.spacing == (1.5, 2.0, 2.5) and volume.origin == (10.0, 20.0, 30.0)
    np.testing.assert_array_equal(volume.data, np.transpose(sections, (2, 1, 0)))   # columns are x

    with mrcfile.new(tmp_path / "ccp4.map") as mrc:   # a CCP4 map storing z in columns, x in rows, y in sections
        mrc.set_data(sections)
        mrc.header.mapc, mrc.header.mapr, mrc.header.maps = 3, 1, 2
        mrc.header.nxstart, mrc.header.nystart, mrc.header.nzstart = 2, 0, 0
        mrc.voxel_size = 1.0
    volume = vio.read(tmp_path / "ccp4.map")
    np.testing.assert_array_equal(volume.data, np.transpose(sections, (1, 0, 2)))  # rows x, sections y, columns z
    assert volume.origin == (2.0, 0.0, 0.0)                       # the start indices times the voxel size

    good = (tmp_path / "map.mrc").read_bytes()
    (tmp_path / "cut.mrc").write_bytes(good[: len(good) - 40])
    with pytest.raises(ReadError, match="cut.mrc: not an MRC / CCP4 map mrcfile can read"):
        vio.read(tmp_path / "cut.mrc")


# -- OME-Zarr / Zarr ---------------------------------------------------------------------------------------------------
def _ome_zarr(path, levels, axes, transforms, zarr_format=2):
    """An OME-Zarr image written with zarr-python: one array per level, NGFF multiscales metadata (0.4 on Zarr v2,
    0.5 under ``attributes.ome`` on Zarr v3)."""
    import zarr

    group = zarr.open_group(str(path), mode="w", zarr_format=zarr_format)
    datasets = []
    for i, (data, transform) in enumerate(zip(levels, transforms)):
        array = group.create_array(str(i), shape=data.shape, dtype=data.dtype, chunks=tuple(max(1, n // 2)
                                                                                        for n in data.shape))
        array[:] = data
        datasets.append({"path": str(i), "coordinateTransformations": transform})
    multiscales = [{"version": "0.4" if zarr_format == 2 else "0.5", "axes": axes, "datasets": datasets}]
    if zarr_format == 2:
        group.attrs["multiscales"] = multiscales
    else:
        group.attrs["ome"] = {"version": "0.5", "multiscales": multiscales}
    return path


ZYX = [{"name": "z", "type": "space", "unit": "micrometer"}, {"name": "y", "type": "space", "unit": "micrometer"},
       {"name": "x", "type": "space", "unit": "micrometer"}]


@pytest.mark.parametrize("zarr_format", [2, 3])
def test_an_ome_zarr_image_at_its_scale_and_translation(tmp_path, zarr_format):
    stack = _stored((4, 6, 8), seed=40)                       # (z, y, x)
    path = _ome_zarr(tmp_path / "cells.ome.zarr", [stack, stack[:, ::2, ::2]], ZYX,
                     [[{"type": "scale", "scale": [2.0, 0.5, 0.25]}, {"type": "translation",
                                                                    "translation": [10.0, 0.0, 5.0]}],
                      [{"type": "scale", "scale": [2.0, 1.0, 0.5]}]], zarr_format)
    assert spec_of(path).name == "zarr"
    volume = vio.read(path)
    assert volume.spacing == (0.25, 0.5, 2.0) and volume.origin == (5.0, 0.0, 10.0) and volume.name == "cells"
    np.testing.assert_array_equal(volume.data, np.transpose(stack, (2, 1, 0)))
    coarse = vio.read(path, level=1)
    assert coarse.spacing == (0.5, 1.0, 2.0)
    np.testing.assert_array_equal(coarse.data, np.transpose(stack[:, ::2, ::2], (2, 1, 0)))


def test_the_finest_ome_zarr_level_that_fits_and_channels_over_time(tmp_path, monkeypatch):
    from volviz_imaging import omezarr

    stack = _stored((2, 3, 4, 6, 8), seed=41)                  # (t, c, z, y, x)
    axes = [{"name": "t", "type": "time"}, {"name": "c", "type": "channel"}] + ZYX
    path = _ome_zarr(tmp_path / "movie.ome.zarr", [stack, stack[..., ::2, ::2]], axes,
                     [[{"type": "scale", "scale": [1.5, 1.0, 1.0, 1.0, 1.0]}],
                      [{"type": "scale", "scale": [1.5, 1.0, 1.0, 2.0, 2.0]}]])
    series = vio.read(path)
    assert isinstance(series, TimeSeries) and list(series.times) == [0.0, 1.5]
    frame = series.frame(1)
    assert frame.arrays["movie"].shape == (8, 6, 4, 3)
    np.testing.assert_array_equal(frame.arrays["movie"], np.transpose(stack[1], (3, 2, 1, 0)))
    monkeypatch.setattr(omezarr, "MAX_VOXELS", 3 * 4 * 6 * 8 - 1)    # level 0 no longer fits one step
    with pytest.warns(ReadWarning, match="showing level 1") as caught:
        smaller = vio.read(path, isolate=False)
    assert smaller.frame(0).dimensions == (4, 3, 4)
    choice = next(w.message for w in caught if isinstance(w.message, ChoiceWarning))
    assert (choice.option, choice.chosen, choice.choices) == ("level", 1, [0, 1])
    assert choice.labels[0].startswith("level 0 (") and choice.labels[0].endswith("— finest")


def test_a_plain_zarr_array_reads_z_y_x(tmp_path):
    import zarr

    stack = _stored((3, 4, 5), seed=42)
    zarr.create_array(str(tmp_path / "plain.zarr"), data=stack)
    volume = vio.read(tmp_path / "plain.zarr")
    np.testing.assert_array_equal(volume.data, np.transpose(stack, (2, 1, 0)))


def test_a_zarr_codec_that_would_unpickle_is_refused_before_anything_is_decoded(tmp_path):
    """A Zarr v2 array may name any numcodecs codec; numcodecs' "pickle" would unpickle the chunk. The chunk here
    would write a marker file when unpickled: it must not exist afterwards."""
    import json
    import pickle

    class Marker:
        def __reduce__(self):
            return (Path.write_text, (tmp_path / "PWNED", "unpickled"))

    folder = tmp_path / "evil.zarr"
    folder.mkdir()
    (folder / ".zarray").write_text(json.dumps({
        "zarr_format": 2, "shape": [2, 2, 2], "chunks": [2, 2, 2], "dtype": "<f4", "fill_value": 0, "order": "C",
        "compressor": None, "filters": [{"id": "pickle", "protocol": 5}], "dimension_separator": "."}))
    (folder / "0.0.0").write_bytes(pickle.dumps(Marker()))
    with pytest.raises(ReadError, match="evil.zarr: its Zarr array uses the codec\\(s\\) pickle, which volviz does "
                                        "not run"):
        vio.read(folder)
    assert not (tmp_path / "PWNED").exists()


def test_a_damaged_zarr_chunk_is_a_read_error(tmp_path):
    import zarr

    stack = _stored((4, 4, 4), seed=43).astype(np.float32)
    zarr.create_array(str(tmp_path / "d.zarr"), data=stack, chunks=(2, 2, 2), zarr_format=2)
    chunk = next(p for p in (tmp_path / "d.zarr").iterdir() if not p.name.startswith("."))
    chunk.write_bytes(chunk.read_bytes()[:7])
    with pytest.raises(ReadError, match="d.zarr: a chunk could not be read"):
        vio.read(tmp_path / "d.zarr")


# -- MINC --------------------------------------------------------------------------------------------------------------
def _minc(name: str) -> Path:
    from nibabel.testing import data_path   # MINC files shipped with nibabel (nibabel writes no MINC)

    return Path(data_path) / name


@pytest.mark.parametrize("name", ["minc1_1_scale.mnc", "minc2_1_scale.mnc", "small.mnc", "minc2_baddim.mnc"])
def test_minc_1_and_2_voxels_are_placed_in_world_space_through_the_files_scaling(name):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")            # minc2_baddim.mnc: "Invalid spacing declaration"
        img = nib.load(_minc(name))
        volume = vio.read(_minc(name))
    values = img.get_fdata()
    assert np.ptp(values) > 0
    _assert_placed(volume, values.astype(volume.data.dtype), img.affine)


@pytest.mark.parametrize("name", ["minc1_4d.mnc", "minc2_4d.mnc", "minc2-4d-d.mnc"])
def test_a_minc_time_dimension_is_a_time_series(name):
    img = nib.load(_minc(name))
    series = vio.read(_minc(name))
    assert isinstance(series, TimeSeries) and len(series) == img.shape[0]
    np.testing.assert_allclose(np.diff(series.times), img.header.get_zooms()[0])
    values = img.get_fdata()
    for t in range(len(series)):
        _assert_placed(series.frame(t), values[t].astype(series.frame(t).data.dtype), img.affine)
    one = vio.read(_minc(name), time_index=1)
    np.testing.assert_array_equal(one.data, series.frame(1).data)


def test_mutated_minc_files_read_consistently_or_raise_read_error(tmp_path):
    import random

    from volviz.bench import robustness as rb

    from conftest import read_mutations

    for name in ("minc1_1_scale.mnc", "minc2_1_scale.mnc"):
        path = tmp_path / name
        data = _minc(name).read_bytes()
        path.write_bytes(data)
        rng = random.Random(name)
        mutations = [rb.flip_bits(data, rng, min(2048, len(data))) for _ in range(16)]
        mutations += [rb.truncate(data, at) for at in sorted(rng.sample(range(1, len(data)), 12))]
        assert read_mutations(path, mutations, truncated_reads_same=False) >= 12


@pytest.mark.parametrize("edit, problem", [
    # the header cut inside the 'image' variable's record: nibabel said "IndexError: index 0 is out of bounds ..."
    (lambda data: data[:100], "MINC 1: its netCDF header does not parse: a variable's record (name, dimensions, "
                              "attributes, type, size and offset) is damaged (IndexError); the file is truncated or "
                              "corrupt"),
    (lambda data: data.replace(b"signtype", b"signt}pe"),
     "MINC 1: the image's signtype is None, not 'signed__' or 'unsigned'"),
    (lambda data: data.replace(b"image-max", b"image-mbx"),
     "MINC 1: the image has no 'image-max' / 'image-min' pair (its value scaling)"),
    (lambda data: data.replace(b"regular__", b"regulaR__", 1),
     "MINC 1: dimension variable 'zspace' has spacing b'regulaR__'; volviz reads 'regular__' only (nibabel's MINC "
     "reader needs it)"),
], ids=["header-cut", "signtype", "image-max", "spacing"])
def test_a_damaged_minc1_header_is_refused_in_minc_terms(tmp_path, edit, problem):
    """Issue #32: these reached the user as nibabel's IndexError, KeyError or AttributeError text alone."""
    from volviz.bench.robustness_formats import _minc1

    _minc1(tmp_path, "int16")
    path = tmp_path / "brain.mnc"
    assert vio.read(path).data.shape == (4, 5, 6)
    path.write_bytes(edit(path.read_bytes()))
    with pytest.raises(ReadError) as info:
        vio.read(path)
    assert str(info.value) == f"{path}: {problem}"


# -- Gaussian cube -----------------------------------------------------------------------------------------------------
BOHR = 0.529177210903


def _cube_file(path: Path, values: np.ndarray, origin, axes, angstrom=False, orbitals=None) -> Path:
    """A cube file as Gaussian's cubegen writes it: values (n1, n2, n3[, orbitals]), six per line, a new line for
    every (i1, i2) row."""
    atoms = [(8, 8.0, 0.0, 0.0, 0.0), (1, 1.0, 1.4, 0.0, 1.1)]
    n_atoms = -len(atoms) if orbitals else len(atoms)
    sign = -1 if angstrom else 1
    lines = ["cube file written by the test", "total density",
             f"{n_atoms:5d} {origin[0]:12.6f} {origin[1]:12.6f} {origin[2]:12.6f}"]
    lines += [f"{sign * n if a == 0 else n:5d} " + " ".join(f"{v:12.6f}" for v in axes[a])
              for a, n in enumerate(values.shape[:3])]
    lines += [f"{z:5d} {q:12.6f} {x:12.6f} {y:12.6f} {w:12.6f}" for z, q, x, y, w in atoms]
    if orbitals:
        lines.append(f"{len(orbitals):5d} " + " ".join(f"{o:5d}" for o in orbitals))
    flat = values.reshape(values.shape[0] * values.shape[1], -1)
    for row in flat:
        lines += [" ".join(f"{v:13.5E}" for v in row[k:k + 6]) for k in range(0, len(row), 6)]
    path.write_text("\n".join(lines) + "\n")
    return path


def _cube_affine(origin, axes, unit) -> np.ndarray:
    affine = np.eye(4)
    affine[:3, :3] = np.asarray(axes, dtype=np.float64).T * unit
    affine[:3, 3] = np.asarray(origin, dtype=np.float64) * unit
    return affine


def _as_written(values: np.ndarray) -> np.ndarray:
    """The values a cube file holds: five decimals of mantissa."""
    return np.vectorize(lambda v: float(f"{v:.5E}"))(values).astype(np.float32)


def test_a_cube_file_is_placed_in_angstrom(tmp_path):
    values = _as_written(np.random.default_rng(7).normal(size=(5, 4, 7)))
    origin, axes = (-3.0, -2.0, -4.5), ((0.0, 0.0, 0.25), (0.5, 0.0, 0.0), (0.0, -0.3, 0.0))   # permuted, flipped
    volume = vio.read(_cube_file(tmp_path / "water.cube", values, origin, axes))
    assert volume.name == "density"
    _assert_placed(volume, values.astype(np.float32), _cube_affine(origin, axes, BOHR))
    in_angstrom = vio.read(_cube_file(tmp_path / "a.cube", values, origin, axes, angstrom=True))
    _assert_placed(in_angstrom, values.astype(np.float32), _cube_affine(origin, axes, 1.0))


def test_an_orbital_cube_shows_one_orbital_and_names_the_others(tmp_path):
    values = _as_written(np.random.default_rng(8).normal(size=(3, 4, 5, 2)))
    axes = ((0.2, 0, 0), (0, 0.2, 0), (0, 0, 0.2))
    path = _cube_file(tmp_path / "mo.cube", values, (0, 0, 0), axes, orbitals=[12, 13])
    with pytest.warns(ReadWarning, match="holds 2 orbitals; showing the first, orbital 12. Others: 13") as caught:
        first = vio.read(path)
    assert first.name == "orbital 12"
    np.testing.assert_array_equal(first.data, values[..., 0])
    choice = next(w.message for w in caught if isinstance(w.message, ChoiceWarning))   # for the app's chooser
    assert (choice.option, choice.chosen, choice.choices) == ("orbital", 12, [12, 13])  # integers, as it takes them
    assert choice.labels == ["orbital 12", "orbital 13"]
    with pytest.warns(ChoiceWarning, match="showing as asked, orbital 13"):
        second = vio.read(path, orbital=choice.choices[1])
    np.testing.assert_array_equal(second.data, values[..., 1])
    with pytest.raises(ReadError, match="mo.cube: holds no orbital 7; its orbitals are 12, 13"):
        vio.read(path, orbital=7)


def test_skewed_and_damaged_cube_files(tmp_path):
    values = np.random.default_rng(9).normal(size=(4, 4, 4))
    skewed = ((0.2, 0.02, 0), (0, 0.2, 0), (0, 0, 0.2))
    with pytest.warns(ReadWarning, match="degrees from the nearest world axes"):
        vio.read(_cube_file(tmp_path / "skew.cube", values, (0, 0, 0), skewed))
    path = _cube_file(tmp_path / "bad.cube", values, (0, 0, 0), ((0.2, 0, 0), (0, 0.2, 0), (0, 0, 0.2)))
    text = path.read_text()
    for broken, problem in [
            (text.replace("    4     0.200000", "  400     0.200000", 1),
             "its header announces 400 x 4 x 4 points.* more than its 896 bytes"),
            (text.rsplit("\n", 3)[0] + "\n", "holds 56 readable values where its header announces 64"),
            (text.replace("E", "Q", 3), "holds text that is not a number among its values"),
            ("\n".join(text.split("\n")[:4]), "is shorter than a cube file's header"),
            (text.replace("    2 ", "  two ", 1), "atom count is text, not an integer")]:
        path.write_text(broken)
        with pytest.raises(ReadError, match=f"bad.cube: {problem}"):
            vio.read(path)


def test_mutated_cube_files_read_consistently_or_raise_read_error(tmp_path):
    import random

    from volviz.bench import robustness as rb

    from conftest import read_mutations

    values = np.random.default_rng(10).normal(size=(4, 5, 6))
    path = _cube_file(tmp_path / "f.cube", values, (0, 0, 0), ((0.2, 0, 0), (0, 0.2, 0), (0, 0, 0.2)))
    data = path.read_bytes()
    rng = random.Random("cube")
    mutations = [rb.flip_bits(data, rng, 500) for _ in range(16)]
    mutations += [rb.truncate(data, at) for at in sorted(rng.sample(range(1, len(data) - 1), 12))]
    assert read_mutations(path, mutations, truncated_reads_same=True) >= 12


@pytest.mark.parametrize("syntax", ["JPEGLosslessProcess14_1", "JPEGLSLossless", "JPEG2000Lossless"])
def test_compressed_dicom_series_read_the_same_voxels(tmp_path, syntax):
    """A series compressed by GDCM into the transfer syntaxes of clinical exports (JPEG Lossless, JPEG-LS,
    JPEG 2000) reads voxel for voxel as the uncompressed series."""
    import gdcm

    values = _stored((4, 12, 10), seed=3)
    names = [f"s{i}.dcm" for i in range(4)]
    dicom_series(tmp_path / "plain", values, (1.0, 0.0, 0.0, 0.0, 1.0, 0.0), (0, 0, 0), (0.5, 0.5), 2.0, names)
    (tmp_path / "packed").mkdir()
    for name in names:
        reader = gdcm.ImageReader()
        reader.SetFileName(str(tmp_path / "plain" / name))
        assert reader.Read()
        change = gdcm.ImageChangeTransferSyntax()
        change.SetTransferSyntax(gdcm.TransferSyntax(getattr(gdcm.TransferSyntax, syntax)))
        change.SetInput(reader.GetImage())
        assert change.Change()
        writer = gdcm.ImageWriter()
        writer.SetFileName(str(tmp_path / "packed" / name))
        writer.SetFile(reader.GetFile())
        writer.SetImage(change.GetOutput())
        assert writer.Write()
    assert pydicom.dcmread(tmp_path / "packed" / names[0]).file_meta.TransferSyntaxUID.is_compressed
    plain, packed = vio.read(tmp_path / "plain"), vio.read(tmp_path / "packed")
    np.testing.assert_array_equal(packed.data, plain.data)
    assert packed.spacing == plain.spacing and packed.origin == plain.origin
