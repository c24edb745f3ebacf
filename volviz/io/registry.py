"""The reader registry: one ``ReaderSpec`` per file format, volviz's own and those plugins add.

A spec says how a format is recognised -- file-name patterns, a content sniffer over the first bytes, the marker
files of a folder it opens, options that select it -- and where its loader lives (``"module:function"``, imported
only when a file of that format is read, so ``import volviz.io`` stays light). Third-party packages add specs
through the entry-point group ``volviz.readers``: each entry point names a ReaderSpec, a list of them, or a
function returning either.

``format_of`` picks the spec of a path:

1. an option that selects a reader (``dims=`` -> raw, ``q=`` -> PLOT3D);
2. a folder: the first spec whose marker file exists in it;
3. by name: among the specs whose patterns match, one whose sniffer accepts the first bytes, else one without a
   sniffer;
4. by content: the first spec whose sniffer accepts the bytes (a format that needs its extension gets a
   "looks like ... give it its extension" error instead);
5. the only spec matching the name (its loader then says what is wrong with the content), else a catch-all spec
   (meshio) matching the name, else a ReadError that lists every supported format.
"""
from __future__ import annotations

import fnmatch
import os
import re
import stat
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Iterable, Union

from volviz.io._checks import check_file, describe_bytes, read_bytes
from volviz.io import isolated
from volviz.io.errors import PathLike, ReadError
from volviz.io.loaders import loader_call, resolve

ENTRY_POINT_GROUP = "volviz.readers"
HEAD_BYTES = 4096
Sniffer = Callable[[bytes], bool]


class PluginWarning(UserWarning):
    """A reader plugin could not be loaded or registers a name that is already taken; it is skipped."""


@dataclass(frozen=True)
class ReaderSpec:
    """One file format volviz reads.

    ``patterns``: globs matched case-insensitively against the file name (``"*.ex2"``), listed in open dialogs; or
    a ``"module:function"`` returning them (computed once, for readers whose list comes from a library).
    ``sniff``: ``f(first_bytes) -> bool`` (or ``"module:function"``) telling whether the content is this format.
    ``loader``: ``"module:function"`` taking ``(path, **options)`` and returning a ``volviz.model`` dataset.
    ``folder_markers``: paths relative to a folder (or globs: any matching file) whose presence means this reader
    opens the folder itself. ``sniffs_folders``: a folder also opens with this reader when one of its first few
    files (by name) passes the sniffer (DICOM series: folders of files often without an extension).
    ``reads_siblings``: the loader reads a file together with the files beside it that belong with it (the slices
    of a DICOM series), so numbered files of this format are not grouped into a time series.
    ``select_options``: options that pick this reader whatever the file is called (``dims`` for raw volumes).
    ``sniff_size``: the sniffer takes the file's size too, ``f(first_bytes, size)`` (``size`` None where it is not
    known): a format recognised by a header that must agree with the file's size (PLOT3D's dimensions).
    ``sniff_opens``: False when the loader needs the file's extension, so a file recognised only by content is
    refused with a hint to rename it. ``claims_name``: False for extensions other formats share (``.dat``, ``.inp``):
    the name then picks this reader only when its sniffer accepts the content too.
    ``catch_all``: match by name only after every other spec failed.
    ``arrays`` and ``options``: what the reader offers and takes, for documentation and ``volviz info``.
    ``isolated``: the loader runs native code that a malformed file can crash (VTK's readers, HDF5, netCDF): ``read``
    runs it in a child process with memory and time limits (``volviz.io.isolated``).
    """

    name: str
    description: str
    patterns: Union[tuple[str, ...], str]
    loader: str
    sniff: Union[Sniffer, str, None] = None
    folder_markers: tuple[str, ...] = ()
    sniffs_folders: bool = False
    reads_siblings: bool = False
    select_options: tuple[str, ...] = ()
    sniff_size: bool = False
    sniff_opens: bool = True
    claims_name: bool = True
    catch_all: bool = False
    arrays: str = ""
    options: tuple[str, ...] = ()
    listed: bool = True
    isolated: bool = False
    _cache: dict = field(default_factory=dict, compare=False, repr=False)

    @property
    def opens_folders(self) -> bool:
        return bool(self.folder_markers) or self.sniffs_folders

    def globs(self) -> tuple[str, ...]:
        """The file-name patterns (resolved and cached on first use when given as ``"module:function"``)."""
        if isinstance(self.patterns, tuple):
            return self.patterns
        if "globs" not in self._cache:
            self._cache["globs"] = tuple(resolve(self.patterns)())
        return self._cache["globs"]

    def matches_name(self, name: str) -> bool:
        low = name.lower()
        return any(fnmatch.fnmatchcase(low, g.lower()) for g in self.globs())

    def accepts(self, head: bytes, size: int | None = None) -> bool:
        """Whether the sniffer recognises ``head`` of a file of ``size`` bytes (False without a sniffer)."""
        if self.sniff is None:
            return False
        sniff: Callable[..., Any] = resolve(self.sniff) if isinstance(self.sniff, str) else self.sniff
        return bool(sniff(head, size) if self.sniff_size else sniff(head))

    def opens_folder(self, folder: Path) -> bool:
        for marker in self.folder_markers:
            found = (next(folder.glob(marker), None) is not None if any(c in marker for c in "*?[")
                     else (folder / marker).exists())
            if found:
                return True
        return self.sniffs_folders and any(self.accepts(_head_or_empty(f)) for f in _first_files(folder))

    def load_function(self) -> Callable[..., Any]:
        return resolve(self.loader)


FOLDER_SNIFF_FILES = 8  # files of a folder a ``sniffs_folders`` spec looks into


def _first_files(folder: Path) -> list[Path]:
    """The first regular files of ``folder`` by name (at most ``FOLDER_SNIFF_FILES``; hidden files skipped)."""
    try:
        names = sorted(e.name for e in os.scandir(folder) if not e.name.startswith(".") and e.is_file())
    except OSError:
        return []
    return [folder / n for n in names[:FOLDER_SNIFF_FILES]]


def _head_or_empty(path: Path) -> bytes:
    try:
        return read_bytes(path, HEAD_BYTES)
    except ReadError:
        return b""


# -- volviz's own readers ----------------------------------------------------------------------------------------------
def _sniff_slc(head: bytes) -> bool:
    return head.lstrip()[:6] in (b"11111\n", b"11111 ", b"11111\r")


def _sniff_metaimage(head: bytes) -> bool:
    low = head[:HEAD_BYTES].lower()
    return b"ndims" in low and b"elementdatafile" in low and b"dimsize" in low


def _sniff_vtk_xml(head: bytes) -> bool:
    m = re.search(rb'<VTKFile[^>]*\btype="([A-Za-z]+)"', head)
    return m is not None and m.group(1) in (b"ImageData", b"UnstructuredGrid", b"StructuredGrid", b"RectilinearGrid",
                                            b"PolyData")


def read_plot3d_auto(path: PathLike, q: PathLike | None = None, **options: Any):
    """PLOT3D grid, with its solution file given as ``q=`` or found next to it by name."""
    # the reader module, imported when its format is read: the registry loads no reader up front
    from volviz.io.plot3d import companion_q_file, read_plot3d

    return read_plot3d(path, q if q is not None else companion_q_file(path), **options)


BUILTIN_READERS: list[ReaderSpec] = [
    ReaderSpec("plot3d", "PLOT3D grid (+ q solution)", ("*.xyz", "*.x", "*.p3d", "*.g", "*.grd", "*xyz*.bin",
                                                         "*xyz*.dat", "*xyz"),
               "volviz.io.registry:read_plot3d_auto", select_options=("q",),
               sniff="volviz.io.plot3d:is_plot3d_grid", sniff_size=True, sniff_opens=False,
               arrays="point: Density, Momentum, StagnationEnergy and derived quantities",
               options=("q", "block", "gamma", "allow_nonfinite")),
    ReaderSpec("pvm", "PVM volume", ("*.pvm", "*.pvm-t*"), "volviz.io.pvm:read_pvm", sniff="volviz.io.pvm:is_pvm",
               arrays="one scalar volume"),
    ReaderSpec("slc", "SLC volume", ("*.slc",), "volviz.io.slc:read_slc", sniff=_sniff_slc, arrays="one scalar volume"),
    ReaderSpec("metaimage", "MetaImage", ("*.mhd", "*.mha"), "volviz.io.metaimage:read_metaimage",
               sniff=_sniff_metaimage, arrays="one scalar volume or image", options=("allow_nonfinite",)),
    ReaderSpec("bov", "VisIt brick of values", ("*.bov",), "volviz.io.bov:read_bov", sniff="volviz.io.bov:is_bov",
               arrays="one array (its components as one array) named by VARIABLE", options=("allow_nonfinite",)),
    ReaderSpec("vtk", "VTK legacy", ("*.vtk",), "volviz.io.vtkfiles:read_vtk_file",
               sniff=lambda head: head.startswith(b"# vtk DataFile"), sniff_opens=False,
               arrays="every point and cell array", options=("allow_nonfinite",), isolated=True),
    ReaderSpec("vtk-xml", "VTK XML", ("*.vti", "*.vtu", "*.vts", "*.vtr", "*.vtp"), "volviz.io.vtkfiles:read_vtk_file",
               sniff=_sniff_vtk_xml, sniff_opens=False, arrays="every point and cell array",
               options=("allow_nonfinite",), isolated=True),
    ReaderSpec("pvd", "ParaView data collection", ("*.pvd",), "volviz.io.pvd:read_pvd", sniff="volviz.io.pvd:is_pvd",
               arrays="the listed VTK files' arrays; time steps as a time series, the parts of a step merged",
               options=("time_index", "allow_nonfinite"), isolated=True),
    ReaderSpec("vtkhdf", "VTKHDF", ("*.vtkhdf", "*.hdf"), "volviz.io.vtkhdf:read_vtkhdf",
               sniff="volviz.io._checks:is_hdf5",
               arrays="every point and cell array; transient files as a time series", options=("allow_nonfinite",),
               isolated=True),
    ReaderSpec("hdf5", "HDF5 arrays", ("*.h5", "*.hdf5", "*.he5", "*.nxs", "*.nx5"), "volviz.io.hdf5arrays:read_hdf5",
               sniff="volviz.io._checks:is_hdf5",
               arrays="the largest numeric 3D / 4D dataset (dataset= picks one), read (z, y, x); VTKHDF as VTK data",
               options=("dataset", "order", "allow_nonfinite"), isolated=True),
    ReaderSpec("matlab", "MATLAB MAT-file", ("*.mat",), "volviz.io.matlab:read_mat", sniff="volviz.io.matlab:is_mat",
               arrays="the largest numeric 3D / 4D variable (variable= picks one), V(r, c, s) at x = c, y = r, z = s",
               options=("variable", "allow_nonfinite"), isolated=True),
    ReaderSpec("pnm", "PGM/PPM image", ("*.pgm", "*.ppm", "*.pnm"), "volviz.io.pnm:read_pnm",
               sniff="volviz.io.pnm:is_pnm", arrays="grey levels or RGB"),
    ReaderSpec("hgt", "SRTM height tile", ("*.hgt",), "volviz.io.elevation:read_hgt",
               arrays="heights in metres (voids at the lowest height)"),
    ReaderSpec("dem", "USGS DEM", ("*.dem",), "volviz.io.dem:read_dem", arrays="heights in metres",
               options=("vtk_compatible",)),
    ReaderSpec("image", "Raster image", ("*.png", "*.jpg", "*.jpeg", "*.tif", "*.tiff", "*.bmp"),
               "volviz.io.image:read_image", arrays="grey levels or RGB; TIFF stacks: a volume, channels as components",
               isolated=True),
    ReaderSpec("npy", "NumPy array", ("*.npy",), "volviz.io.npy:read_npy", sniff="volviz.io.npy:is_npy",
               arrays="the array: (z, y, x) volume, (z, y, x, channels), (t, z, y, x) or a 2D image",
               options=("order", "allow_nonfinite")),
    ReaderSpec("csv", "Point table", ("*.csv", "*.tsv"), "volviz.io.csv_points:read_csv_points",
               arrays="points at the x, y, z columns (x=, y=, z= name others), the other numeric columns on them",
               options=("x", "y", "z", "allow_nonfinite"), isolated=True),
    ReaderSpec("points-text", "Point table (text)", ("*.xyz", "*.pts", "*.txt"),
               "volviz.io.csv_points:read_text_points",
               sniff="volviz.io.csv_points:is_point_text", claims_name=False,
               arrays="points at the first three columns (or those named x, y, z), the other columns on them",
               options=("x", "y", "z", "allow_nonfinite"), isolated=True),
    ReaderSpec("raw", "Raw volume", (), "volviz.io.raw:read_raw", select_options=("dims",), listed=False,
               arrays="one scalar volume", options=("dims", "dtype", "byteorder", "header_bytes")),
    ReaderSpec("meshio", "Meshes (meshio)", "volviz.io.registry:meshio_globs", "volviz.io.meshio_reader:read_meshio",
               catch_all=True, arrays="every point and cell array", options=("file_format", "allow_nonfinite"),
               isolated=True),
]


def meshio_globs() -> tuple[str, ...]:
    # the reader module, imported when its formats are listed: the registry loads no reader up front
    from volviz.io.meshio_reader import meshio_extensions

    return tuple(f"*{e}" for e in meshio_extensions())


# -- the registry -----------------------------------------------------------------------------------------------------
_registry: list[ReaderSpec] | None = None


def _plugin_specs() -> Iterable[ReaderSpec]:
    # importlib.metadata (about 40 modules), loaded only when plugins' entry points are looked up
    from importlib.metadata import entry_points

    for ep in entry_points(group=ENTRY_POINT_GROUP):
        try:
            value = ep.load()
            if callable(value) and not isinstance(value, ReaderSpec):
                value = value()
            items = [value] if isinstance(value, ReaderSpec) else list(value)
            bad = [type(v).__name__ for v in items if not isinstance(v, ReaderSpec)]
            if bad:
                raise TypeError(f"yields {', '.join(bad)} instead of ReaderSpec")
        except Exception as exc:  # a broken plugin must not break reading other files
            warnings.warn(f"reader plugin {ep.name!r} ({ep.value}) is skipped: {exc}", PluginWarning, stacklevel=3)
            continue
        yield from items


def reader_specs(refresh: bool = False) -> list[ReaderSpec]:
    """Every registered reader: volviz's own first, then the plugins' (in entry-point order), the catch-all last.

    The entry points are read once; ``refresh=True`` reads them again (after installing a plugin at run time).
    """
    global _registry
    if _registry is None or refresh:
        specs = [s for s in BUILTIN_READERS if not s.catch_all]
        taken = {s.name for s in BUILTIN_READERS}
        for spec in _plugin_specs():
            if spec.name in taken:
                warnings.warn(f"reader plugin spec {spec.name!r} is skipped: the name is already registered",
                              PluginWarning, stacklevel=2)
                continue
            taken.add(spec.name)
            specs.append(spec)
        _registry = specs + [s for s in BUILTIN_READERS if s.catch_all]
    return _registry


def get_reader(name: str) -> ReaderSpec:
    """The spec registered under ``name``; KeyError listing the names otherwise."""
    for spec in reader_specs():
        if spec.name == name:
            return spec
    raise KeyError(f"no reader named {name!r}; registered: {', '.join(s.name for s in reader_specs())}")


def supported_formats() -> list[tuple[str, tuple[str, ...]]]:
    """``[(description, (glob, ...)), ...]`` of the formats ``read`` recognises by name (for Open dialogs).

    The catch-all reader (meshio) lists only the extensions no other reader claims.
    """
    out: list[tuple[str, tuple[str, ...]]] = []
    taken: set[str] = set()
    for spec in reader_specs():
        if not spec.listed:
            continue
        globs = tuple(g for g in spec.globs() if g.lower() not in taken) if spec.catch_all else spec.globs()
        taken.update(g.lower() for g in globs)
        if globs:
            out.append((spec.description, globs))
    return out


def open_dialog_filter() -> str:
    """A Qt-style file filter string: ``All supported (...);;PVM volume (*.pvm *.pvm-t*);;...;;All files (*)``."""
    formats = supported_formats()
    everything = " ".join(g for _, globs in formats for g in globs)
    parts = [f"All supported ({everything})"] + [f"{d} ({' '.join(g)})" for d, g in formats] + ["All files (*)"]
    return ";;".join(parts)


def _described(specs: Iterable[ReaderSpec]) -> str:
    return "; ".join(f"{s.description} ({' '.join(s.globs())})" for s in specs)


def _folder_spec(p: Path) -> ReaderSpec:
    for spec in reader_specs():
        if spec.opens_folder(p):
            return spec
    folders = [s for s in reader_specs() if s.opens_folders]
    known = "; ".join(f"{s.description} (holding {' or '.join(_folder_signs(s))})" for s in folders)
    raise ReadError(p, "is a directory, not a file" + (f", and not a folder volviz opens: {known}" if known else "")
                    + "; nor does it hold one collection file (.pvd, .xdmf, .vtm, .foam, .case) or a numbered "
                      "series of data files")


def _folder_signs(spec: ReaderSpec) -> tuple[str, ...]:
    return spec.folder_markers + ((f"{spec.description} files",) if spec.sniffs_folders else ())


def _is_dir(path: PathLike) -> bool:
    try:
        return stat.S_ISDIR(os.stat(os.fspath(path)).st_mode)
    except (OSError, ValueError, TypeError):
        return False


def spec_of(path: PathLike, options: dict | None = None) -> ReaderSpec:
    """The reader spec for ``path`` (see the module docstring for the order); ReadError if none fits."""
    options = options or {}
    specs = reader_specs()
    for spec in specs:
        if any(k in options for k in spec.select_options):
            return spec
    if _is_dir(path):
        return _folder_spec(Path(os.fspath(path)))
    p = check_file(path)
    head = read_bytes(p, HEAD_BYTES)
    size = p.stat().st_size
    named = [s for s in specs if not s.catch_all and s.matches_name(p.name) and
             (s.claims_name or s.accepts(head, size))]
    for candidates in ([s for s in named if s.accepts(head, size)], [s for s in named if s.sniff is None]):
        if candidates:
            return candidates[0]
    for spec in specs:
        if spec.accepts(head, size):
            if not spec.sniff_opens:
                raise ReadError(p, f"looks like a {spec.description} file; give it its extension "
                                   f"({' '.join(g[1:] for g in spec.globs())})")
            return spec
    if len(named) == 1:
        return named[0]  # its loader says what is wrong with the content
    if named:
        raise ReadError(p, f"is named like {' or '.join(s.description for s in named)}, but its content fits none of "
                           f"them (its content is {describe_bytes(head)})")
    catch_all = [s for s in specs if s.catch_all and s.matches_name(p.name)]
    if catch_all:
        return catch_all[0]
    ext = p.suffix.lower()
    if ext == ".raw":
        headers = sorted(h.name for h in p.parent.glob(p.stem + ".mh[da]"))
        if headers:
            raise ReadError(p, f"is the raw data of {headers[0]}",
                            f"open {headers[0]}, the header that describes it")
        raise ReadError(p, "is raw data without a header: volviz needs its dimensions and sample type",
                        "write a MetaImage header (.mhd) naming them next to it and open that; volviz-app guesses "
                        "the layout from the data and writes that header for you (in Python: "
                        "volviz.io.raw_layout.guess_layouts, volviz.io.read_raw)")
    if re.search(r"\.\d+$", p.name):
        raise ReadError(p, "looks like one slice of a stack of numbered slices without a header: volviz needs the "
                           "slices' size and sample type",
                        "write a MetaImage header (.mhd) whose ElementDataFile lists the slices (or a pattern) and "
                        "open that; volviz-app guesses the layout from the data and writes that header for you (in "
                        "Python: volviz.io.raw_layout.guess_layouts, volviz.io.read_slice_stack)")
    raise ReadError(p, f"unknown data format (extension {ext or 'none'!r}, content: {describe_bytes(head)}); "
                       "supported: " + _described(s for s in specs if s.listed))


def format_of(path: PathLike, options: dict) -> str:
    """The name of the reader spec for ``path``: from options, folder markers, the name, else the content."""
    return spec_of(path, options).name


def call_reader(kind: str, path: PathLike, options: dict, isolate: bool | None = None):
    """Call the reader registered as ``kind`` (see ``loader_call`` for the options).

    A spec marked ``isolated`` runs in a child process (``volviz.io.isolated``) unless ``isolate=False`` or the
    environment variable ``VOLVIZ_ISOLATE=0`` turns isolation off (for debugging a reader in one process).
    """
    spec = get_reader(kind)
    if spec.isolated:
        if isolated.isolation_enabled(isolate):
            return isolated.read_isolated(spec, path, options)
    f, opts = loader_call(kind, spec.loader, options)
    return f(os.fspath(path), **opts)


def is_pattern(path: Any) -> bool:
    """A list of paths, or a glob / printf pattern that is not itself the name of an existing file."""
    if isinstance(path, (list, tuple)):
        return True
    if not isinstance(path, (str, os.PathLike)):
        return False
    text = os.fspath(path)
    if isinstance(text, bytes) or os.path.lexists(text):
        return False
    return any(c in text for c in "*?[") or re.search(r"%0?\d*d", text) is not None
