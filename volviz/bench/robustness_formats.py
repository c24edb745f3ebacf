"""Seeds of the formats the first campaign left out, for ``volviz bench robustness`` (issue #32).

XDMF, Tecplot, EnSight, AVS UCD, OME-Zarr, MINC, plain HDF5 arrays, CSV points, text point clouds (.xyz), BOV, PVD,
LAZ and volviz's own ``.vvz``: each seed is a small valid dataset written at run time by the format's own library
(meshio, h5py, zarr-python, SciPy's netCDF writer, laspy, pyvista, volviz's codec) or, where no library writes it,
as the format's documentation lays it out (EnSight Gold ASCII, Tecplot ASCII, BOV). Several seeds per format differ
in shape, type or layout. A seed may be several files (a header and its data, a collection and its pieces, a Zarr
folder): each of its files that a reader interprets is a mutation target of its own, the other files are put
beside it unchanged. Fluent CFF, Tecplot and XDMF also come from ``../shared/data/ecosystem`` (``_KINDS`` of
``volviz.bench.robustness``). Each seed names VTK's reader of the format where VTK has one.
"""
from __future__ import annotations

import datetime
import json
import os
import random
import shutil
import struct
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np


@dataclass(frozen=True)
class Seed:
    """One seed: ``write(folder)`` writes its files; ``target`` is what is read (relative to the folder; "" the
    folder itself); ``mutate`` the files damaged, each (relative path, header layout, byte order); ``vtk`` VTK's
    reader recipe or None."""

    fmt: str
    label: str
    write: Callable[[Path], None]
    target: str
    mutate: tuple[tuple[str, str, str], ...]
    vtk: str | None = None


def _grid(n: tuple[int, int, int]) -> np.ndarray:
    """Distinct values on a (z, y, x) grid."""
    return (np.arange(int(np.prod(n)), dtype=np.int64) * 37 % 251).reshape(n)


def _tets() -> tuple[np.ndarray, np.ndarray]:
    """A cube of 8 points split into 5 tetrahedra (points, 0-based connectivity)."""
    pts = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=np.float64) * [1.0, 2.0, 0.5]
    cells = np.array([[0, 1, 2, 4], [1, 3, 2, 7], [1, 4, 5, 7], [2, 4, 6, 7], [1, 2, 4, 7]])
    return pts, cells


# -- writers -----------------------------------------------------------------------------------------------------------
def _xdmf(folder: Path, steps: int) -> None:
    """A time series of a tetrahedral mesh (meshio's TimeSeriesWriter, as FEniCS and meshio users write it). The
    writer puts its heavy data file in the working folder: it is written there, then moved beside the XDMF file."""
    # meshio: only the robustness seeds in its format need it (imported where they are written)
    import meshio

    pts, cells = _tets()
    here = os.getcwd()
    with tempfile.TemporaryDirectory(prefix="volviz-xdmf-") as tmp:
        os.chdir(tmp)
        try:
            with meshio.xdmf.TimeSeriesWriter("mesh.xdmf") as w:
                w.write_points_cells(pts, [("tetra", cells)])
                for t in range(steps):
                    w.write_data(float(t), point_data={"T": pts[:, 0] + 10 * t + pts[:, 2]})
        finally:
            os.chdir(here)
        for name in ("mesh.xdmf", "mesh.h5"):
            shutil.move(os.path.join(tmp, name), folder / name)


def _tecplot_ordered(folder: Path) -> None:
    n = (2, 3, 4)
    v = _grid(n).astype(float) / 7.0
    lines = ['TITLE = "volviz robustness"', 'VARIABLES = "X", "Y", "Z", "T"',
             f'ZONE T="block", I={n[2]}, J={n[1]}, K={n[0]}, DATAPACKING=POINT']
    lines += [f"{x * 0.5:g} {y * 0.25:g} {z * 2.0:g} {v[z, y, x]:.6g}"
              for z in range(n[0]) for y in range(n[1]) for x in range(n[2])]
    (folder / "block.dat").write_text("\n".join(lines) + "\n")


def _tecplot_fe(folder: Path) -> None:
    pts, cells = _tets()
    lines = ['TITLE = "tets"', 'VARIABLES = "X" "Y" "Z" "P"',
             f'ZONE T="tets", N={len(pts)}, E={len(cells)}, DATAPACKING=POINT, ZONETYPE=FETETRAHEDRON']
    lines += [f"{x:g} {y:g} {z:g} {x + 2 * y - z:g}" for x, y, z in pts]
    lines += [" ".join(str(i + 1) for i in c) for c in cells]
    (folder / "tets.dat").write_text("\n".join(lines) + "\n")


def _ensight(folder: Path) -> None:
    """EnSight Gold ASCII: a case file, a geometry of one part (5 tetrahedra) and a scalar per node."""
    pts, cells = _tets()
    geo = ["EnSight Gold geometry", "written by volviz bench robustness", "node id off", "element id off",
           "part", f"{1:10d}", "cube", "coordinates", f"{len(pts):10d}"]
    geo += [f"{v:12.5e}" for axis in range(3) for v in pts[:, axis]]
    geo += ["tetra4", f"{len(cells):10d}"] + ["".join(f"{i + 1:10d}" for i in c) for c in cells]
    (folder / "mesh.geo").write_text("\n".join(geo) + "\n")
    scl = ["temperature", "part", f"{1:10d}", "coordinates"] + [f"{x + y + z:12.5e}" for x, y, z in pts]
    (folder / "temp.scl").write_text("\n".join(scl) + "\n")
    (folder / "mesh.case").write_text("FORMAT\ntype: ensight gold\n\nGEOMETRY\nmodel: mesh.geo\n\nVARIABLE\n"
                                      "scalar per node: temperature temp.scl\n")


def _avs(folder: Path, hexahedra: bool) -> None:
    # meshio: only the robustness seeds in its format need it (imported where they are written)
    import meshio

    pts, cells = _tets()
    blocks = [("hexahedron", np.array([[0, 1, 3, 2, 4, 5, 7, 6]]))] if hexahedra else [("tetra", cells)]
    meshio.write(str(folder / "mesh.inp"), meshio.Mesh(pts, blocks, point_data={"T": pts[:, 0] * 3},
                                                      cell_data={"id": [np.arange(len(blocks[0][1]), dtype=float)]}),
                 file_format="avsucd")


def _zarr(folder: Path, chunks: tuple[int, int, int], compressor: str) -> None:
    # optional: zarr (a reader plugin's dependency), only to write the files it reads
    import zarr

    values = _grid((6, 5, 4)).astype(np.uint16)
    root = zarr.open_group(str(folder / "image.zarr"), mode="w", zarr_format=2)
    codec = {"zlib": __import__("numcodecs").Zlib(level=1), "none": None}[compressor]
    a = root.create_array("0", shape=values.shape, chunks=chunks, dtype=values.dtype, compressors=codec)
    a[:] = values
    axes = [{"name": n, "type": "space", "unit": "micrometer"} for n in "zyx"]
    root.attrs["multiscales"] = [{"version": "0.4", "axes": axes, "datasets": [
        {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [2.0, 0.5, 0.5]}]}]}]


def _minc1(folder: Path, dtype: str) -> None:
    """MINC 1: a netCDF classic file (SciPy's writer) with the image, its per-slice image-min / image-max and the
    three space dimensions' step, start and direction cosines, as minc-toolkit writes them."""
    # heavy: SciPy, only for this case
    from scipy.io import netcdf_file

    values = _grid((6, 5, 4)).astype(dtype)
    with netcdf_file(str(folder / "brain.mnc"), "w", version=1) as f:
        for name, n, step in zip(("zspace", "yspace", "xspace"), values.shape, (2.0, 1.0, 0.5)):
            f.createDimension(name, n)
            var = f.createVariable(name, "d", ())
            var.step, var.start, var.spacing, var.units = step, -10.0, "regular__", "mm"
            var.direction_cosines = np.eye(3)["xyz".index(name[0])]
            var.varid, var.vartype, var.version = "MINC standard variable", "dimension____", "MINC Version    1.0"
        img = f.createVariable("image", values.dtype.char, ("zspace", "yspace", "xspace"))
        img[:] = values
        img.valid_range = np.array([0.0, 250.0])
        img.signtype = "unsigned" if values.dtype.kind == "u" else "signed__"
        img.varid, img.vartype, img.version = "MINC standard variable", "group________", "MINC Version    1.0"
        for name, value in (("image-max", 250.0), ("image-min", 0.0)):
            v = f.createVariable(name, "d", ("zspace",))
            v[:] = value
            v.varid, v.vartype, v.version = "MINC standard variable", "var_attribute", "MINC Version    1.0"


def _hdf5(folder: Path, chunked: bool) -> None:
    # h5py: only the robustness seeds in its format need it (imported where they are written)
    import h5py

    values = _grid((6, 5, 4)).astype(np.float32)
    with h5py.File(folder / "tomo.h5", "w") as f:
        ds = f.create_dataset("entry/data", data=values, chunks=(3, 5, 4) if chunked else None,
                              compression="gzip" if chunked else None)
        ds.attrs["element_size_um"] = np.array([2.0, 1.0, 1.0])


def _points(n: int) -> np.ndarray:
    i = np.arange(n, dtype=np.float64)
    return np.column_stack([i * 0.37, (i * 7 % 40) * 0.5, 100.0 + i % 17, (i * 97) % 255])


def _csv(folder: Path, sep: str) -> None:
    rows = _points(60)
    text = sep.join(("x", "y", "z", "value")) + "\n" + "\n".join(sep.join(f"{v:.6g}" for v in r) for r in rows)
    (folder / "points.csv").write_text(text + "\n")


def _xyz(folder: Path, columns: int) -> None:
    rows = _points(80)[:, :columns]
    (folder / "cloud.xyz").write_text("\n".join(" ".join(f"{v:.6g}" for v in r) for r in rows) + "\n")


def _bov(folder: Path, fmt: str, dtype: str, endian: str, centering: str) -> None:
    values = _grid((6, 5, 4)).astype(np.dtype(dtype).newbyteorder("<" if endian == "LITTLE" else ">"))
    (folder / "brick.raw").write_bytes(values.tobytes())
    (folder / "brick.bov").write_text(
        "TIME: 1.5\nDATA_FILE: brick.raw\nDATA_SIZE: 4 5 6\nDATA_FORMAT: " + fmt + "\nVARIABLE: density\n"
        f"DATA_ENDIAN: {endian}\nCENTERING: {centering}\nBRICK_ORIGIN: 0. 0. 0.\nBRICK_SIZE: 4. 5. 12.\n")


def _pvd(folder: Path) -> None:
    # heavy: PyVista (VTK), only to write the seeds in VTK's formats
    import pyvista as pv

    entries = []
    for t in range(3):
        grid = pv.ImageData(dimensions=(4, 5, 6), spacing=(0.5, 0.5, 2.0))
        grid.point_data["v"] = (_grid((6, 5, 4)).ravel() + t).astype(np.float32)
        grid.save(str(folder / f"step_{t}.vti"), binary=t != 1)
        entries.append(f'    <DataSet timestep="{t * 0.5}" part="0" file="step_{t}.vti"/>')
    (folder / "run.pvd").write_text('<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n'
                                    "  <Collection>\n" + "\n".join(entries) + "\n  </Collection>\n</VTKFile>\n")


LAZ_DATE = datetime.date(2026, 1, 1)   # the LAZ seeds' creation date, so that --replay rebuilds them any day


def _laz(folder: Path, point_format: int, version: str) -> None:
    import laspy  # type: ignore[import-untyped]   # laspy ships no type information

    header = laspy.LasHeader(point_format=point_format, version=version)
    header.creation_date = LAZ_DATE   # laspy stamps today's date: a seed written another day was another file
    header.scales, header.offsets = np.array([0.01, 0.01, 0.01]), np.array([1000.0, 2000.0, 0.0])
    las = laspy.LasData(header)
    p = _points(150)
    las.x, las.y, las.z = 1000.0 + p[:, 0], 2000.0 + p[:, 1], p[:, 2]
    las.intensity = p[:, 3].astype(np.uint16)
    las.write(str(folder / "cloud.laz"), laz_backend=laspy.LazBackend.Lazrs)


def _vvz(folder: Path, mode: str, dtype: str) -> None:
    # the kernels (Numba) of this case only: a bench loads what its cases run
    from volviz.model import RegularVolume
    from volviz.regular.codec import compress

    values = np.ascontiguousarray(_grid((20, 18, 17)).astype(dtype).transpose(2, 1, 0))  # x, y, z
    compress(RegularVolume(data=values, spacing=(1.0, 1.0, 2.0), name="v"), folder / "v.vvz", mode=mode,
             quality=0.5 if mode == "quality" else None)


# -- the seeds ---------------------------------------------------------------------------------------------------------
_XML, _TEXT, _BIN, _H5, _NONE = "xml", "text", "binary", "hdf5", "none"
_Z = "image.zarr/"
SEEDS: tuple[Seed, ...] = (
    Seed("xdmf", "tets-1", lambda f: _xdmf(f, 1), "mesh.xdmf", (("mesh.xdmf", _XML, "<"), ("mesh.h5", _H5, "<")),
         "xdmf"),
    Seed("xdmf", "tets-3", lambda f: _xdmf(f, 3), "mesh.xdmf", (("mesh.xdmf", _XML, "<"), ("mesh.h5", _H5, "<")),
         "xdmf"),
    Seed("tecplot", "ordered", _tecplot_ordered, "block.dat", (("block.dat", _TEXT, ">"),), "tecplot"),
    Seed("tecplot", "fe", _tecplot_fe, "tets.dat", (("tets.dat", _TEXT, ">"),), "tecplot"),
    Seed("ensight", "gold-ascii", _ensight, "mesh.case",
         (("mesh.case", _TEXT, ">"), ("mesh.geo", _TEXT, ">"), ("temp.scl", _TEXT, ">")), "ensight"),
    Seed("avs-ucd", "tets", lambda f: _avs(f, False), "mesh.inp", (("mesh.inp", _TEXT, ">"),), "avs"),
    Seed("avs-ucd", "hexahedron", lambda f: _avs(f, True), "mesh.inp", (("mesh.inp", _TEXT, ">"),), "avs"),
    Seed("ome-zarr", "zlib", lambda f: _zarr(f, (3, 5, 4), "zlib"), "image.zarr",
         ((_Z + ".zattrs", "json", ">"), (_Z + "0/.zarray", "json", ">"), (_Z + "0/0.0.0", _BIN, "<"))),
    Seed("ome-zarr", "raw-chunks", lambda f: _zarr(f, (2, 2, 2), "none"), "image.zarr",
         ((_Z + "0/.zarray", "json", ">"), (_Z + "0/1.1.1", _NONE, "<"))),
    Seed("minc", "minc1-short", lambda f: _minc1(f, "int16"), "brain.mnc", (("brain.mnc", _BIN, ">"),), "minc"),
    Seed("minc", "minc1-float", lambda f: _minc1(f, "float32"), "brain.mnc", (("brain.mnc", _BIN, ">"),), "minc"),
    Seed("hdf5", "contiguous", lambda f: _hdf5(f, False), "tomo.h5", (("tomo.h5", _H5, "<"),)),
    Seed("hdf5", "gzip", lambda f: _hdf5(f, True), "tomo.h5", (("tomo.h5", _H5, "<"),)),
    Seed("csv", "comma", lambda f: _csv(f, ","), "points.csv", (("points.csv", _TEXT, ">"),)),
    Seed("csv", "semicolon", lambda f: _csv(f, ";"), "points.csv", (("points.csv", _TEXT, ">"),)),
    Seed("xyz", "xyz", lambda f: _xyz(f, 3), "cloud.xyz", (("cloud.xyz", _TEXT, ">"),), "xyz"),
    Seed("xyz", "xyzi", lambda f: _xyz(f, 4), "cloud.xyz", (("cloud.xyz", _TEXT, ">"),), "xyz"),
    Seed("bov", "float-nodal", lambda f: _bov(f, "FLOAT", "f4", "LITTLE", "nodal"), "brick.bov",
         (("brick.bov", _TEXT, ">"), ("brick.raw", _NONE, "<"))),
    Seed("bov", "short-zonal", lambda f: _bov(f, "SHORT", "i2", "BIG", "zonal"), "brick.bov",
         (("brick.bov", _TEXT, ">"), ("brick.raw", _NONE, "<"))),
    Seed("pvd", "three-steps", _pvd, "run.pvd", (("run.pvd", _XML, "<"), ("step_0.vti", _XML, "<"),
                                                 ("step_1.vti", _XML, "<"))),
    Seed("laz", "format1-v12", lambda f: _laz(f, 1, "1.2"), "cloud.laz", (("cloud.laz", _BIN, "<"),)),
    Seed("laz", "format6-v14", lambda f: _laz(f, 6, "1.4"), "cloud.laz", (("cloud.laz", _BIN, "<"),)),
    Seed("vvz", "lossless-u8", lambda f: _vvz(f, "lossless", "uint8"), "v.vvz", (("v.vvz", "vvz", "<"),)),
    Seed("vvz", "quality-f32", lambda f: _vvz(f, "quality", "float32"), "v.vvz", (("v.vvz", "vvz", "<"),)),
)

FORMATS = sorted({s.fmt for s in SEEDS})


def write_seeds(folder: Path, formats: list[str] | None = None) -> list[tuple[Seed, Path]]:
    """Write every seed (of the formats named, else all) into a folder of its own under ``folder``; a seed whose
    library is not installed is left out. Returns (seed, its folder)."""
    written = []
    for seed in SEEDS:
        if formats and seed.fmt not in formats:
            continue
        where = folder / f"{seed.fmt}-{seed.label}"
        where.mkdir(parents=True, exist_ok=True)
        try:
            seed.write(where)
        except ImportError:
            continue
        written.append((seed, where))
    return written


# -- mutations of volviz's own container: consistent checksums over inconsistent content -------------------------------
#: what a metadata field or a brick-table field of a ``.vvz`` file is set to
VVZ_VALUES: tuple[object, ...] = (0, -1, 1, 2**31 - 1, 2**63 - 1, 1e308, float("nan"), "", "int64", "V100000000",
                                  "float128", "object", [], {}, None, True, [1, 2], [[[[[[1]]]]]])


def vvz_mutation(data: bytes, rng: random.Random, kind: str) -> tuple[str, bytes] | None:
    """``vvz-meta``: one metadata field (or one entry of a list field) set to one of ``VVZ_VALUES``, or removed;
    ``vvz-table``: one field of one brick record set to 0, 1, -1 (as unsigned), 2^31-1 or another record's value.
    The metadata is written again (the table moves after it) and every CRC of the header is recomputed, so the file
    passes its checksums: only the reader's checks of the content against itself can refuse it (the issue's
    "dtype changed to int64 with recomputed checksums"). None when the file's header no longer parses."""
    # the kernels (Numba) of this case only: a bench loads what its cases run
    from volviz.regular.container import _HDR, BRICK_DTYPE, crc32

    try:
        magic, version, hsize, flags, meta_off, meta_len, table_off, count, _m, _t, res = _HDR.unpack(data[:60])
        meta = json.loads(data[meta_off:meta_off + meta_len])
        table = np.frombuffer(data[table_off:table_off + count * 32], BRICK_DTYPE).copy()
    except (struct.error, ValueError, UnicodeDecodeError):
        return None
    if not isinstance(meta, dict) or not meta or len(table) != count:
        return None
    if kind == "vvz-meta":
        key = rng.choice(sorted(meta))
        old = meta[key]
        if rng.random() < 0.1:
            del meta[key]
            what = f"metadata field {key!r} removed"
        elif isinstance(old, list) and old and rng.random() < 0.6:
            i = rng.randrange(len(old))
            old[i] = rng.choice(VVZ_VALUES)
            what = f"metadata field {key!r}[{i}] set to {old[i]!r}"
        else:
            meta[key] = rng.choice(VVZ_VALUES)
            what = f"metadata field {key!r} ({old!r}) set to {meta[key]!r}"
    else:
        if not len(table):
            return None
        i, name = rng.randrange(len(table)), rng.choice(list(BRICK_DTYPE.names or ()))
        info = np.iinfo(BRICK_DTYPE[name])
        value = rng.choice((0, 1, info.max, min(info.max, 2**31 - 1), int(table[rng.randrange(len(table))][name])))
        what = f"brick {i} {name} ({int(table[i][name])}) set to {value}"
        table[i][name] = value
    meta_bytes = json.dumps(meta, sort_keys=True).encode()
    table_bytes = table.tobytes()
    head = _HDR.pack(magic, version, hsize, flags, meta_off, len(meta_bytes), meta_off + len(meta_bytes), count,
                     crc32(meta_bytes), crc32(table_bytes), res)
    head += struct.pack("<I", crc32(head))
    return what, head + data[len(head):meta_off] + meta_bytes + table_bytes


def _json_slots(obj: object, path: tuple = ()) -> list[tuple]:
    """The path of every value inside a parsed JSON document (object keys and list indices)."""
    found = [path] if path else []
    items = obj.items() if isinstance(obj, dict) else enumerate(obj) if isinstance(obj, list) else ()
    for key, value in items:
        found += _json_slots(value, (*path, key))
    return found


def json_mutation(data: bytes, rng: random.Random) -> tuple[str, bytes] | None:
    """One value anywhere in a JSON metadata file (a Zarr ``.zarray`` / ``.zattrs``) set to one of ``VVZ_VALUES``
    or removed: a document that still parses and says something else (a shape, a dtype, a scale, an axis)."""
    try:
        doc = json.loads(data)
    except (ValueError, UnicodeDecodeError):
        return None
    slots = _json_slots(doc)
    if not slots:
        return None
    path = rng.choice(slots)
    parent = doc
    for key in path[:-1]:
        parent = parent[key]
    old = parent[path[-1]]
    if rng.random() < 0.1:
        del parent[path[-1]]
        what = f"JSON value at {list(path)} ({json.dumps(old)[:30]}) removed"
    else:
        parent[path[-1]] = rng.choice(VVZ_VALUES)
        what = f"JSON value at {list(path)} ({json.dumps(old)[:30]}) set to {parent[path[-1]]!r}"
    return what, json.dumps(doc, indent=4).encode()
