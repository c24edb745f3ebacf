"""Format dispatch for ``volviz.io.read``: by extension first, then by the file's magic bytes."""
from __future__ import annotations

import inspect
import os
import re
from pathlib import Path
from typing import Any, Callable

from volviz.io._checks import check_file, read_bytes
from volviz.io.errors import PathLike, ReadError

# (description, glob patterns) for open dialogs; order = how they are listed
FORMATS: list[tuple[str, tuple[str, ...]]] = [
    ("PLOT3D grid (+ q solution)", ("*.xyz", "*.x", "*.p3d", "*xyz*.bin")),
    ("PVM volume", ("*.pvm", "*.pvm-t*")),
    ("SLC volume", ("*.slc",)),
    ("MetaImage", ("*.mhd", "*.mha")),
    ("VTK legacy", ("*.vtk",)),
    ("VTK XML", ("*.vti", "*.vtu", "*.vts", "*.vtr", "*.vtp")),
    ("VTKHDF", ("*.vtkhdf", "*.hdf")),
    ("PGM/PPM image", ("*.pgm", "*.ppm", "*.pnm")),
    ("USGS DEM", ("*.dem",)),
    ("Raster image", ("*.png", "*.jpg", "*.jpeg", "*.tif", "*.tiff", "*.bmp")),
]
_PVM_NAME = re.compile(r"\.pvm(-t\d+)?$", re.I)
_PLOT3D_EXT = {".xyz", ".x", ".p3d", ".g", ".grd"}


def _loader(kind: str) -> Callable[..., Any]:
    """The reader function of a format kind (imported lazily, so ``import volviz.io`` stays light)."""
    if kind == "pvm":
        from volviz.io.pvm import read_pvm as f
    elif kind == "pnm":
        from volviz.io.pnm import read_pnm as f
    elif kind == "slc":
        from volviz.io.slc import read_slc as f
    elif kind == "dem":
        from volviz.io.dem import read_dem as f
    elif kind == "metaimage":
        from volviz.io.metaimage import read_metaimage as f
    elif kind == "vtk":
        from volviz.io.vtkfiles import read_vtk_file as f
    elif kind == "vtkhdf":
        from volviz.io.vtkhdf import read_vtkhdf as f
    elif kind == "plot3d":
        f = _read_plot3d_auto
    elif kind == "raw":
        from volviz.io.raw import read_raw as f
    elif kind == "meshio":
        from volviz.io.meshio_reader import read_meshio as f
    elif kind == "image":
        from volviz.io.image import read_image as f
    else:  # pragma: no cover
        raise KeyError(kind)
    return f


def _read_plot3d_auto(path: PathLike, q: PathLike | None = None, **options):
    from volviz.io.plot3d import companion_q_file, read_plot3d

    return read_plot3d(path, q if q is not None else companion_q_file(path), **options)


def _sniff(path: Path, head: bytes) -> str | None:
    from volviz.io.pnm import is_pnm
    from volviz.io.pvm import is_pvm

    if is_pvm(head):
        return "pvm"
    if is_pnm(head):
        return "pnm"
    if head.lstrip()[:6] == b"11111\n" or head.lstrip()[:6] == b"11111 " or head.lstrip()[:6] == b"11111\r":
        return "slc"
    if head.startswith(b"# vtk DataFile"):
        return "vtk"
    if head.startswith(b"\x89HDF\r\n\x1a\n"):
        return "vtkhdf"
    low = head[:4096].lower()
    if b"ndims" in low and b"elementdatafile" in low and b"dimsize" in low:
        return "metaimage"
    return None


def format_of(path: PathLike, options: dict) -> str:
    """The format kind of ``path``: from the extension, else the magic bytes; ReadError if unknown."""
    p = check_file(path)
    name = p.name.lower()
    ext = p.suffix.lower()
    if _PVM_NAME.search(name):
        return "pvm"
    by_ext = {".pgm": "pnm", ".ppm": "pnm", ".pnm": "pnm", ".slc": "slc", ".dem": "dem", ".mhd": "metaimage",
              ".mha": "metaimage", ".vtk": "vtk", ".vti": "vtk", ".vtu": "vtk", ".vts": "vtk", ".vtr": "vtk",
              ".vtp": "vtk", ".vtkhdf": "vtkhdf", ".hdf": "vtkhdf", ".png": "image", ".jpg": "image",
              ".jpeg": "image", ".tif": "image", ".tiff": "image", ".bmp": "image"}
    if "dims" in options:
        return "raw"
    if ext in by_ext:
        return by_ext[ext]
    if ext in _PLOT3D_EXT or "q" in options or ("xyz" in name and ext in (".bin", ".dat", "")):
        return "plot3d"
    head = read_bytes(p, 4096)
    sniffed = _sniff(p, head)
    if sniffed is not None:
        if sniffed == "vtk" and ext not in (".vtk",):
            raise ReadError(p, "looks like a VTK legacy file; give it the .vtk extension")
        return sniffed
    if head.lstrip().startswith((b"<?xml", b"<VTKFile")):
        raise ReadError(p, "looks like a VTK XML file; give it its .vti/.vtu/.vts/.vtr/.vtp extension")
    if ext == ".raw":
        raise ReadError(p, "a .raw file has no header: call volviz.io.read_raw(path, dims, dtype, byteorder) or "
                           "open the .mhd header that describes it")
    from volviz.io.meshio_reader import meshio_extensions

    if ext and ext in meshio_extensions():
        return "meshio"
    if re.search(r"\.\d+$", name):
        raise ReadError(p, "looks like one slice of a numbered stack; use volviz.io.read_slice_stack(pattern, "
                           "dims, dtype, byteorder) or read_series(pattern)")
    raise ReadError(p, f"unknown data format (extension {ext or 'none'!r}, first bytes {head[:8]!r}); supported: "
                       + "; ".join(f"{d} ({' '.join(g)})" for d, g in FORMATS) + "; and meshio's formats")


def call_reader(kind: str, path: PathLike, options: dict):
    """Call the reader of ``kind``; ``allow_nonfinite`` is dropped for readers of integer-only formats, any
    other option the reader does not take is a TypeError naming it."""
    f = _loader(kind)
    params = inspect.signature(f).parameters
    accepts_kwargs = any(p.kind is inspect.Parameter.VAR_KEYWORD for p in params.values())
    opts = dict(options)
    if "allow_nonfinite" in opts and "allow_nonfinite" not in params and not accepts_kwargs:
        opts.pop("allow_nonfinite")
    unknown = [k for k in opts if k not in params and not accepts_kwargs]
    if unknown:
        raise TypeError(f"the {kind} reader does not take option(s) {', '.join(unknown)}")
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
