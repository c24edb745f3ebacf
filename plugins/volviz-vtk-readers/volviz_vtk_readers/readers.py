"""The loaders of the VTK-readers plugin: each a top-level ``read_x(path, **options)`` returning a volviz dataset.

Every loader checks the file cheaply first (exists, regular file or the right kind of folder, magic bytes, for
netCDF/HDF5 containers that the file is as long as its header says), then runs VTK's reader with its messages
captured into a ReadError (``volviz.io.vtkfiles._run``), and converts with ``volviz.io.vtkconvert.vtk_to_model``,
which keeps every point and cell array and merges composite data with vtkAppendFilter.

A file with several time steps (the reader's TIME_STEPS) becomes a ``TimeSeries``: frame 0 is read at once, later
frames lazily through ``read_x(path, time_index=i, **options)`` -- a picklable call, so frames can be read in
another process. ``time_index=i`` reads one step as a plain dataset.

Blocks (option ``blocks=[names]``; ``list_blocks(path)`` lists the names). A block is named by its path in the
file's block tree (``"SQNZ/dom1_1_1_1"``) or by its last part (``"dom1_1_1_1"``); the chosen blocks are merged.
"""
from __future__ import annotations

import functools
from pathlib import Path
from typing import Any, Callable, Iterator, Sequence

import numpy as np

from volviz.io._checks import check_file, describe_bytes, read_bytes
from volviz.io.errors import PathLike, ReadError
from volviz.io.vtkconvert import vtk_to_model
from volviz.io.vtkfiles import _run
from volviz.model import TimeSeries

from volviz_vtk_readers import specs, xdmf
from volviz_vtk_readers.avscheck import check_avs_ucd
from volviz_vtk_readers.containers import check_container
from volviz_vtk_readers.ensightcheck import check_ensight_case
from volviz_vtk_readers.exodus_check import check_exodus_connectivity
from volviz_vtk_readers.foamcheck import check_time_folder
from volviz_vtk_readers.tecplotcheck import check_tecplot_zones


class _Pass:
    """A VTK reader seen by ``vtkfiles._run`` as doing one pipeline pass: the information pass only, or the data
    of one time step; everything else goes to the reader itself."""

    def __init__(self, reader: Any, information: bool = False, time: float | None = None) -> None:
        self._reader, self._information, self._time = reader, information, time

    def Update(self) -> None:  # noqa: N802 - VTK's name
        if self._information:
            self._reader.UpdateInformation()
        elif self._time is None:
            self._reader.Update()
        else:
            self._reader.UpdateTimeStep(self._time)

    def __getattr__(self, name: str) -> Any:
        return getattr(self._reader, name)


def _information(path: PathLike, reader: Any) -> Any:
    _run(path, _Pass(reader, information=True))
    return reader


def _time_steps(reader: Any) -> list[float]:
    from volviz.io.vtk_lazy import vtk

    info = reader.GetOutputInformation(0)
    key = vtk.vtkStreamingDemandDrivenPipeline.TIME_STEPS()
    return [info.Get(key, i) for i in range(info.Length(key))] if info.Has(key) else []


def _frame(loader: Callable[..., Any], path: str, options: dict, index: int):
    return loader(path, time_index=index, **options)


def _in_time(path: PathLike, reader: Any, loader: Callable[..., Any], options: dict, time_index: int | None,
             convert: Callable[[Any], Any]):
    """The reader's data as one dataset (one time step) or a TimeSeries over its TIME_STEPS."""
    times = _time_steps(reader)
    if time_index is not None:
        if not 0 <= time_index < max(len(times), 1):
            raise ReadError(path, f"time_index {time_index} is out of range: the file has {max(len(times), 1)} "
                                  "time step(s)")
        return convert(_run(path, _Pass(reader, time=times[time_index] if times else None)))
    first = convert(_run(path, _Pass(reader, time=times[0] if times else None)))
    if len(times) <= 1:
        return first
    frames: list[Any] = [first] + [None] * (len(times) - 1)
    return TimeSeries(np.asarray(times, dtype=np.float64), frames,
                      loader=functools.partial(_frame, loader, str(path), options), source=str(path))


# -- blocks ------------------------------------------------------------------------------------------------------------
def _leaves(obj: Any, prefix: str = "") -> Iterator[tuple[str, Any]]:
    """``(path, data set)`` of every non-empty block of a composite data set; a partitioned data set is one block."""
    from volviz.io.vtk_lazy import vtk

    if obj is None:
        return
    if obj.IsA("vtkMultiBlockDataSet") or obj.IsA("vtkPartitionedDataSetCollection"):
        multi = obj.IsA("vtkMultiBlockDataSet")
        count = obj.GetNumberOfBlocks() if multi else obj.GetNumberOfPartitionedDataSets()
        for i in range(count):
            name = obj.GetMetaData(i).Get(vtk.vtkCompositeDataSet.NAME()) if obj.HasMetaData(i) else None
            child = obj.GetBlock(i) if multi else obj.GetPartitionedDataSet(i)
            yield from _leaves(child, f"{prefix}{name or f'block{i}'}/")
    elif obj.IsA("vtkPartitionedDataSet") or (obj.IsA("vtkDataSet") and obj.GetNumberOfPoints() > 0):
        if not obj.IsA("vtkPartitionedDataSet") or any(
                obj.GetPartition(j) is not None and obj.GetPartition(j).GetNumberOfPoints() > 0
                for j in range(obj.GetNumberOfPartitions())):
            yield prefix.rstrip("/"), obj


def _pick(path: PathLike, available: Sequence[str], blocks: Sequence[str] | str) -> list[str]:
    """The names of ``available`` that ``blocks`` ask for (full path or last part); ReadError for unknown names."""
    wanted = [blocks] if isinstance(blocks, str) else list(blocks)
    chosen, unknown = [], []
    for name in wanted:
        hits = [a for a in available if a == name or a.rsplit("/", 1)[-1] == name]
        chosen += [h for h in hits if h not in chosen]
        if not hits:
            unknown.append(name)
    if unknown or not chosen:
        raise ReadError(path, f"no block named {', '.join(map(repr, unknown)) or 'at all'}; the file's blocks are: "
                              f"{', '.join(available) or 'none'}")
    return chosen


def _select_leaves(path: PathLike, obj: Any, blocks: Sequence[str] | str | None) -> Any:
    """``obj`` with only the chosen blocks (one block is returned as itself, keeping its structured type)."""
    from volviz.io.vtk_lazy import vtk

    if blocks is None or not obj.IsA("vtkCompositeDataSet"):
        return obj
    leaves = dict(_leaves(obj))
    chosen = _pick(path, list(leaves), blocks)
    if len(chosen) == 1:
        return leaves[chosen[0]]
    out = vtk.vtkMultiBlockDataSet()
    for i, name in enumerate(chosen):
        out.SetBlock(i, leaves[name])
    return out


def _convert(path: PathLike, blocks: Sequence[str] | str | None, allow_nonfinite: bool) -> Callable[[Any], Any]:
    return lambda obj: vtk_to_model(path, _select_leaves(path, obj, blocks), allow_nonfinite=allow_nonfinite)


# -- checks ------------------------------------------------------------------------------------------------------------
def _check_sniffed(path: PathLike, sniff: Callable[[bytes], bool], what: str) -> Path:
    p = check_file(path)
    head = read_bytes(p, 4096)
    if not sniff(head):
        raise ReadError(p, f"not a {what} file (its content is {describe_bytes(head)})")
    return p


def _reader(cls: str, file_name: PathLike, setter: str = "SetFileName") -> Any:
    from volviz.io.vtk_lazy import vtk

    reader = getattr(vtk, cls)()
    getattr(reader, setter)(str(file_name))
    return reader


# -- Exodus II ---------------------------------------------------------------------------------------------------------
def _exodus(path: PathLike) -> Any:
    from volviz.io.vtk_lazy import vtk

    check_container(path, "Exodus II")
    check_exodus_connectivity(path)            # VTK reads past its point array for a node number out of range
    reader = _information(path, _reader("vtkExodusIIReader", path))
    for kind in (vtk.vtkExodusIIReader.NODAL, vtk.vtkExodusIIReader.ELEM_BLOCK):
        for i in range(reader.GetNumberOfObjectArrays(kind)):
            reader.SetObjectArrayStatus(kind, i, 1)
    return reader


def _exodus_blocks(reader: Any) -> list[str]:
    from volviz.io.vtk_lazy import vtk

    kind = vtk.vtkExodusIIReader.ELEM_BLOCK
    return [reader.GetObjectName(kind, i) for i in range(reader.GetNumberOfObjects(kind))]


def read_exodus(path: PathLike, blocks: Sequence[str] | str | None = None, time_index: int | None = None,
                allow_nonfinite: bool = True):
    """Exodus II: every element block (or ``blocks``) with every nodal and element variable, merged."""
    from volviz.io.vtk_lazy import vtk

    reader = _exodus(path)
    if blocks is not None:
        names = _exodus_blocks(reader)
        chosen = set(_pick(path, names, blocks))
        for i, name in enumerate(names):
            reader.SetObjectStatus(vtk.vtkExodusIIReader.ELEM_BLOCK, i, int(name in chosen))
    return _in_time(path, reader, read_exodus, {"blocks": blocks, "allow_nonfinite": allow_nonfinite}, time_index,
                    _convert(path, None, allow_nonfinite))


# -- OpenFOAM ----------------------------------------------------------------------------------------------------------
def _openfoam(path: PathLike) -> Any:
    p = Path(path)
    if p.is_dir():
        if not (p / "system" / "controlDict").is_file():
            raise ReadError(p, "is a folder but not an OpenFOAM case: it holds no system/controlDict")
        file_name = p / "system" / "controlDict"
    else:
        p = check_file(path)
        if not (p.parent / "system" / "controlDict").is_file():
            raise ReadError(p, f"is not inside an OpenFOAM case: {p.parent} holds no system/controlDict")
        if not (p.parent / "constant" / "polyMesh").is_dir() and not any(p.parent.glob("processor*")):
            raise ReadError(p, f"the OpenFOAM case {p.parent} has no constant/polyMesh (nor processor* folders)")
        file_name = p
    reader = _reader("vtkOpenFOAMReader", file_name)
    reader.CreateCellToPointOn()
    reader.ReadZonesOff()
    _information(path, reader)
    reader.EnableAllCellArrays()
    reader.EnableAllPointArrays()
    return reader


def _check_openfoam_time(path: PathLike, reader: Any, index: int) -> None:
    """The field files of the time step about to be read are complete (``foamcheck``): VTK drops a damaged one
    silently."""
    names = reader.GetTimeNames()
    if names is not None and 0 <= index < names.GetNumberOfValues():
        case = Path(path) if Path(path).is_dir() else Path(path).parent
        check_time_folder(case, case / names.GetValue(index))


def _openfoam_blocks(reader: Any) -> list[str]:
    return [reader.GetPatchArrayName(i) for i in range(reader.GetNumberOfPatchArrays())]


def read_openfoam(path: PathLike, blocks: Sequence[str] | str | None = None, time_index: int | None = None,
                  allow_nonfinite: bool = True):
    """OpenFOAM (a ``.foam`` file in the case folder, or the folder): the internal mesh by default, every field as
    cell data and interpolated to the points; ``blocks=["patch/movingWall", ...]`` picks patches instead or too."""
    reader = _openfoam(path)
    _check_openfoam_time(path, reader, time_index or 0)
    names = _openfoam_blocks(reader)
    chosen = set(_pick(path, names, blocks)) if blocks is not None else {"internalMesh"}
    for name in names:
        reader.SetPatchArrayStatus(name, int(name in chosen))
    return _in_time(path, reader, read_openfoam, {"blocks": blocks, "allow_nonfinite": allow_nonfinite}, time_index,
                    _convert(path, None, allow_nonfinite))


# -- CGNS, EnSight, Tecplot, Fluent, multiblock VTK: blocks chosen from the output tree -------------------------------
def _cgns(path: PathLike) -> Any:
    from volviz_vtk_readers.cgnshdf5 import check_cgns_hdf5

    p = check_container(path, "CGNS", netcdf=False, adf=True)  # ADF: the node tree is walked there
    check_cgns_hdf5(p)  # HDF5: every object's metadata and dataset sizes
    reader = _information(path, _reader("vtkCGNSReader", path))
    reader.EnableAllBases()
    reader.EnableAllPointArrays()
    reader.EnableAllCellArrays()
    return reader


def read_cgns(path: PathLike, blocks: Sequence[str] | str | None = None, time_index: int | None = None,
              allow_nonfinite: bool = True):
    """CGNS: every zone of every base (or ``blocks``: ``"Base/Zone"`` or ``"Zone"``), merged."""
    return _in_time(path, _cgns(path), read_cgns, {"blocks": blocks, "allow_nonfinite": allow_nonfinite}, time_index,
                    _convert(path, blocks, allow_nonfinite))


def _ensight(path: PathLike) -> Any:
    _check_sniffed(path, specs.is_ensight_case, "EnSight case")
    check_ensight_case(path)  # VTK's reader loops on a damaged case file and reads files cut short as other values
    reader = _information(path, _reader("vtkGenericEnSightReader", path, "SetCaseFileName"))
    reader.ReadAllVariablesOn()
    return reader


def read_ensight(path: PathLike, blocks: Sequence[str] | str | None = None, time_index: int | None = None,
                 allow_nonfinite: bool = True):
    """EnSight (.case): every part (or ``blocks``) with every variable, merged."""
    return _in_time(path, _ensight(path), read_ensight, {"blocks": blocks, "allow_nonfinite": allow_nonfinite},
                    time_index, _convert(path, blocks, allow_nonfinite))


def _tecplot(path: PathLike) -> Any:
    p = _check_sniffed(path, specs.is_tecplot, "Tecplot ASCII")
    if read_bytes(p, 5) == b"#!TDV":
        raise ReadError(p, "is a binary Tecplot file (#!TDV); VTK reads Tecplot ASCII only: export it as ASCII "
                           "(e.g. Tecplot's preplot -a or 'Write Data File' ASCII)")
    check_tecplot_zones(p)  # VTK's reader loops or returns an empty mesh on a zone cut short
    return _information(path, _reader("vtkTecplotReader", path))


def read_tecplot(path: PathLike, blocks: Sequence[str] | str | None = None, allow_nonfinite: bool = True):
    """Tecplot ASCII: every zone (or ``blocks``) with every variable, merged."""
    output = _run(path, _tecplot(path))  # every variable is read
    if output is None or output.GetNumberOfPoints() == 0:
        raise ReadError(path, "VTK's Tecplot reader found no zone with points in it",
                        "check the file's ZONE headers and values")
    return _convert(path, blocks, allow_nonfinite)(output)


def _fluent(path: PathLike) -> Any:
    p = _check_sniffed(path, specs.is_fluent, "Fluent")
    if p.suffix.lower() == ".dat":
        case = p.with_suffix(".cas")
        if not case.is_file():
            raise ReadError(p, f"is a Fluent data file; its case file {case.name} is not beside it (open the .cas)")
        p = _check_sniffed(case, specs.is_fluent, "Fluent case")
    reader = _information(p, _reader("vtkFLUENTReader", p))
    reader.EnableAllCellArrays()
    return reader


def read_fluent(path: PathLike, blocks: Sequence[str] | str | None = None, allow_nonfinite: bool = True):
    """Fluent (.cas with its .dat beside it): every cell zone (or ``blocks``) with every cell field, merged."""
    return _convert(path, blocks, allow_nonfinite)(_run(path, _fluent(path)))


def _vtk_xml(path: PathLike, sniff: Callable[[bytes], bool], what: str) -> str:
    """The data set type of a VTK XML file whose type ``sniff`` accepts."""
    p = _check_sniffed(path, sniff, what)
    return specs.xml_type(read_bytes(p, 4096))


_XML_CLASSES = {"vtkMultiBlockDataSet": "vtkXMLMultiBlockDataReader",
                "vtkPartitionedDataSetCollection": "vtkXMLPartitionedDataSetCollectionReader",
                "vtkPartitionedDataSet": "vtkXMLPartitionedDataSetReader",
                "PUnstructuredGrid": "vtkXMLPUnstructuredGridReader", "PImageData": "vtkXMLPImageDataReader",
                "PStructuredGrid": "vtkXMLPStructuredGridReader", "PRectilinearGrid": "vtkXMLPRectilinearGridReader",
                "PPolyData": "vtkXMLPPolyDataReader"}


def _vtk_multiblock(path: PathLike) -> Any:
    return _reader(_XML_CLASSES[_vtk_xml(path, specs.is_vtk_multiblock, "VTK multiblock XML")], path)


def read_vtk_multiblock(path: PathLike, blocks: Sequence[str] | str | None = None, allow_nonfinite: bool = True):
    """.vtm / .vtpd: every block (or ``blocks``) with every array, merged."""
    return _convert(path, blocks, allow_nonfinite)(_run(path, _vtk_multiblock(path)))


def read_vtk_parallel(path: PathLike, allow_nonfinite: bool = True):
    """.pvtu / .pvti / .pvts / .pvtr / .pvtp: the pieces joined by VTK's parallel XML reader."""
    reader = _reader(_XML_CLASSES[_vtk_xml(path, specs.is_vtk_parallel, "VTK parallel XML")], path)
    return vtk_to_model(path, _run(path, reader), allow_nonfinite=allow_nonfinite)


# -- netCDF CF ---------------------------------------------------------------------------------------------------------
def read_netcdf_cf(path: PathLike, dimensions: str | None = None, spherical: bool = True,
                   time_index: int | None = None, allow_nonfinite: bool = True):
    """netCDF with CF conventions: every variable on ``dimensions`` (default: the reader's first set, e.g.
    ``"(lat, lon)"``); fill values become NaN; lat/lon grids on the unit sphere unless ``spherical=False``."""
    check_container(path, "netCDF", cf=True)
    reader = _reader("vtkNetCDFCFReader", path)
    reader.SetSphericalCoordinates(bool(spherical))
    reader.ReplaceFillValueWithNanOn()
    _information(path, reader)
    sets = reader.GetAllDimensions()
    available = [sets.GetValue(i) for i in range(sets.GetNumberOfValues())]
    if not available:
        raise ReadError(path, "holds no variable on a grid (no coordinate dimensions VTK's netCDF CF reader knows)")
    if dimensions is not None and dimensions not in available:
        raise ReadError(path, f"no variables on dimensions {dimensions!r}; the file has {', '.join(available)}")
    reader.SetDimensions(dimensions or available[0])  # enables every variable on these dimensions
    _information(path, reader)
    options = {"dimensions": dimensions, "spherical": spherical, "allow_nonfinite": allow_nonfinite}
    return _in_time(path, reader, read_netcdf_cf, options, time_index, _convert(path, None, allow_nonfinite))


# -- XDMF --------------------------------------------------------------------------------------------------------------
def _xdmf(path: PathLike) -> Any:
    _check_sniffed(path, xdmf.is_xdmf, "XDMF")
    return _information(path, _reader("vtkXdmfReader", path))


def read_xdmf(path: PathLike, blocks: Sequence[str] | str | None = None, time_index: int | None = None,
              allow_nonfinite: bool = True):
    """XDMF 2/3: the temporal collections (or every grid, or ``blocks``); blocks on one mesh as one data set with
    all their fields (``volviz_vtk_readers.xdmf``)."""
    found = xdmf.outline(path)
    xdmf.check_heavy_data(path, found)
    temporal = found.temporal if blocks is None else []
    reader = _xdmf(path)

    def convert(obj: Any) -> Any:
        leaves = list(_leaves(_select_leaves(path, obj, blocks)))
        if not leaves:
            raise ReadError(path, "holds no grid with points")
        joined = xdmf.fields_on_shared_meshes(xdmf.shown_leaves(leaves, temporal))
        return vtk_to_model(path, joined, allow_nonfinite=allow_nonfinite)

    return _in_time(path, reader, read_xdmf, {"blocks": blocks, "allow_nonfinite": allow_nonfinite}, time_index,
                    convert)


# -- AVS UCD -----------------------------------------------------------------------------------------------------------
def read_avs_ucd(path: PathLike, allow_nonfinite: bool = True):
    """AVS UCD (.inp, ASCII or binary): the mesh with every node and cell component."""
    p = _check_sniffed(path, specs.is_avs_ucd, "AVS UCD")
    check_avs_ucd(p)  # VTK's reader reads a file cut within its node or cell lines as other values
    reader = _reader("vtkAVSucdReader", p)
    reader.SetBinaryFile(read_bytes(p, 1) == b"\x07")
    _information(p, reader)
    reader.EnableAllPointArrays()
    reader.EnableAllCellArrays()
    return vtk_to_model(path, _run(path, reader), allow_nonfinite=allow_nonfinite)


# -- block listing -----------------------------------------------------------------------------------------------------
def _fluent_cff(path: PathLike) -> Any:
    from volviz_vtk_readers.fluentcff import fluent_cff_reader

    return fluent_cff_reader(path)


_TREE_READERS: dict[str, Callable[[PathLike], Any]] = {
    "cgns": _cgns, "ensight": _ensight, "tecplot": _tecplot, "fluent": _fluent, "fluent-cff": _fluent_cff,
    "vtk-multiblock": _vtk_multiblock, "xdmf": _xdmf}


def list_blocks(path: PathLike) -> list[str]:
    """The names ``blocks=`` takes for this file: Exodus element blocks, OpenFOAM ``internalMesh`` and
    ``patch/...`` names, CGNS ``Base/Zone``, EnSight parts, Tecplot and Fluent zones, .vtm/.vtpd blocks, XDMF
    grids.
    Formats without blocks give ``[]``."""
    from volviz.io.registry import spec_of

    kind = spec_of(path).name
    if kind in ("hdf5", "vtkhdf"):  # a format on HDF5 under a generic name (.h5): the reader it goes to
        from volviz.io.hdf5kind import KINDS, hdf5_kind

        found = hdf5_kind(path)
        kind = KINDS[found][0] if found is not None else kind
    if kind == "exodus":
        return _exodus_blocks(_exodus(path))
    if kind == "openfoam":
        return _openfoam_blocks(_openfoam(path))
    if kind in _TREE_READERS:
        return [name for name, _ in _leaves(_run(path, _TREE_READERS[kind](path)))]
    return []
