"""XDMF (``.xdmf``, ``.xmf``; versions 2 and 3, heavy data in HDF5, binary or inline XML) through VTK's
``vtkXdmfReader``: the format of FEniCS / dolfinx, meshio's time series and many HPC codes.

What opens by default, and why:

- A file whose domain holds temporal collections (``GridType="Collection" CollectionType="Temporal"``) shows those
  collections: dolfinx writes the mesh once as a grid of its own and each function as a temporal collection that
  includes the mesh's geometry and topology. The bare mesh grid carries no field, and merged with the functions it
  would lay the same cells over themselves.
- Blocks on one and the same mesh (the same points and cells; dolfinx's ``u`` and ``p`` collections) are fields of
  that mesh: one data set with every block's arrays (an array name two blocks share gets the block's name after it).
  Blocks on different meshes are merged as other formats' blocks are.
- ``blocks=`` picks grids by name instead; time steps come from the file (a ``TimeSeries``).

Before VTK's reader sees the file, a streaming pass over the XML (expat: no entity expansion bombs, no XInclude
processing) finds the top-level grids and the HDF5 data items; each item's file must exist and its dataset hold the
values its ``Dimensions`` declare (VTK's reader reads past a smaller dataset and crashes). The same pass holds every
attribute of a fixed kind to its field (``check_attribute``): a number must parse (a ``Time`` whose ``Value`` is
``T`` was read by VTK as time 0, a second step at the same time), a keyword must be one of the XDMF model's
(compared without case, as Xdmf2 does), so two attribute values swapped are refused naming the element, the
attribute and the value instead of read as something else (issue #32).
"""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from volviz.io._checks import check_file, describe_bytes, read_bytes
from volviz.io.errors import PathLike, ReadError


def is_xdmf(head: bytes) -> bool:
    """An XML file whose root element is ``<Xdmf``."""
    return b"<Xdmf" in head[:4096]


@dataclass
class Outline:
    """What a pass over an XDMF file's markup finds: its top-level temporal collections (names, in file order) and
    its HDF5 data items (declared dimensions, file as written, dataset path)."""

    temporal: list[str] = field(default_factory=list)
    hdf5_items: list[tuple[tuple[int, ...], str, str]] = field(default_factory=list)


def _dimensions(p: Path, text: str | None) -> tuple[int, ...] | None:
    if text is None:
        return None
    try:
        dims = tuple(int(v) for v in text.split())
    except ValueError:
        raise ReadError(p, "a DataItem's Dimensions are not whole numbers") from None
    if not dims or min(dims) < 0:
        raise ReadError(p, "a DataItem's Dimensions are not sizes")
    return dims


#: keyword attributes of the XDMF model (Xdmf2 and XDMF 3 names, lower case: Xdmf compares them without case)
KEYWORDS: dict[tuple[str, str], frozenset[str]] = {
    ("DataItem", "NumberType"): frozenset({"float", "int", "uint", "char", "uchar"}),
    ("DataItem", "DataType"): frozenset({"float", "int", "uint", "char", "uchar"}),
    ("DataItem", "Format"): frozenset({"xml", "hdf", "binary", "tiff"}),
    ("DataItem", "Endian"): frozenset({"native", "big", "little"}),
    ("DataItem", "ItemType"): frozenset({"uniform", "collection", "tree", "hyperslab", "coordinates", "function"}),
    ("Attribute", "Center"): frozenset({"node", "cell", "grid", "face", "edge", "other"}),
    ("Attribute", "AttributeType"): frozenset({"scalar", "vector", "tensor", "tensor6", "matrix", "globalid"}),
    ("Grid", "GridType"): frozenset({"uniform", "collection", "tree", "subset"}),
    ("Grid", "CollectionType"): frozenset({"spatial", "temporal"}),
    ("Geometry", "GeometryType"): frozenset({"xyz", "xy", "x_y_z", "x_y", "vxvyvz", "origin_dxdydz", "origin_dxdy",
                                             "polar", "spherical"}),
    ("Time", "TimeType"): frozenset({"single", "hyperslab", "list", "range"}),
}
#: attributes that hold whole numbers: (element, attribute) -> how many (None: one or more)
WHOLE_NUMBERS: dict[tuple[str, str], int | None] = {
    ("DataItem", "Precision"): 1, ("DataItem", "Dimensions"): None, ("DataItem", "Seek"): 1,
    ("Topology", "NumberOfElements"): None, ("Topology", "Dimensions"): None, ("Topology", "NodesPerElement"): 1,
    ("Attribute", "Dimensions"): None,
}


def check_attribute(p: Path, tag: str, name: str, value: str) -> None:
    """ReadError unless ``value`` is a valid value of the attribute ``name`` of an element ``tag``: a keyword of the
    model (``KEYWORDS``), a whole number >= 0 (``WHOLE_NUMBERS``; ``Precision`` 1, 2, 4 or 8) or a finite number
    (``Time``'s ``Value``); other attributes (names, references) are free text."""
    where = f"{'an' if tag[0] in 'AEIOU' else 'a'} {tag} element's {name} {value[:40]!r}"
    allowed = KEYWORDS.get((tag, name))
    if allowed is not None and value.strip().lower() not in allowed:
        raise ReadError(p, f"{where} is not one of XDMF's ({', '.join(sorted(allowed))})")
    count = WHOLE_NUMBERS.get((tag, name), 0)
    if count != 0:
        words = value.split()
        if not words or not all(w.isdigit() for w in words) or (count is not None and len(words) != count):
            raise ReadError(p, f"{where} " + ("is not a whole number" if count == 1 else "are not whole numbers >= 0"))
        if name == "Precision" and words[0] not in ("1", "2", "4", "8"):
            raise ReadError(p, f"{where} is not a byte count XDMF knows (1, 2, 4 or 8)")
    if (tag, name) == ("Time", "Value"):
        try:
            times = [float(w) for w in value.replace(",", " ").split()]
        except ValueError:
            times = []
        if not times or not all(math.isfinite(t) for t in times):
            raise ReadError(p, f"{where} is not a finite number (a time step)")


def outline(path: PathLike) -> Outline:
    """The file's ``Outline``, from one streaming pass over its XML; ReadError if it is not XDMF or does not
    parse."""
    p = check_file(path)
    head = read_bytes(p, 4096)
    if not is_xdmf(head):
        raise ReadError(p, f"is not an XDMF file (no <Xdmf> element; its content is {describe_bytes(head)})")
    found = Outline()
    depth, domain_depth = 0, -1
    wrapped: list[bool] = []      # per open DataItem: whether it combines others (HyperSlab, Function ...)
    try:
        for event, element in ET.iterparse(p, events=("start", "end")):
            tag = element.tag.rsplit("}", 1)[-1]
            if event == "start":
                depth += 1
                for name, value in element.attrib.items():
                    check_attribute(p, tag, name, value)
                if tag == "Domain" and domain_depth < 0:
                    domain_depth = depth
                elif (tag == "Grid" and depth == domain_depth + 1 and element.get("GridType") == "Collection"
                      and element.get("CollectionType") == "Temporal"):
                    found.temporal.append(element.get("Name") or f"grid{len(found.temporal)}")
                elif tag == "DataItem":
                    wrapped.append(element.get("ItemType", "Uniform") != "Uniform")
                continue
            depth -= 1
            if tag == "DataItem":
                wrapped.pop()
                text = (element.text or "").strip()
                if element.get("Format") == "HDF" and not any(wrapped) and ":" in text:
                    dims = _dimensions(p, element.get("Dimensions"))
                    name, dataset = text.rsplit(":", 1)
                    if dims is not None:
                        found.hdf5_items.append((dims, name.strip(), dataset.strip()))
            element.clear()
    except ET.ParseError as exc:
        raise ReadError(p, f"its XML does not parse ({exc})") from None
    return found


def check_heavy_data(path: PathLike, found: Outline) -> None:
    """Every HDF5 data item's file exists and its dataset holds at least the values its Dimensions declare: VTK's
    reader reads past the dataset otherwise (and crashes)."""
    import h5py

    p = Path(path)
    for dims, name, dataset in found.hdf5_items:
        heavy = Path(name) if Path(name).is_absolute() else p.parent / name
        if not heavy.is_file():
            raise ReadError(p, f"its heavy data file {name} is missing (looked for {heavy})")
        try:
            with h5py.File(heavy, "r") as f:
                item = f.get(dataset)
                size = item.size if isinstance(item, h5py.Dataset) else None
        except OSError as exc:
            raise ReadError(heavy, f"is not a readable HDF5 file ({exc})") from None
        if size is None:
            raise ReadError(p, f"names the dataset {dataset} in {name}, which {name} does not hold")
        if size < math.prod(dims):
            raise ReadError(p, f"declares {' x '.join(map(str, dims))} values in {name}:{dataset}, which holds "
                               f"{size}")


def _arrays(data: Any) -> list[Any]:
    return [data.GetAbstractArray(i) for i in range(data.GetNumberOfArrays())]


def _same_mesh(a: Any, b: Any) -> bool:
    """Whether two VTK data sets have the same class, points and cells."""
    from vtkmodules.util.numpy_support import vtk_to_numpy

    if a.GetClassName() != b.GetClassName() or a.GetNumberOfPoints() != b.GetNumberOfPoints() \
            or a.GetNumberOfCells() != b.GetNumberOfCells():
        return False
    if a.IsA("vtkImageData"):
        return (a.GetDimensions() == b.GetDimensions() and np.allclose(a.GetOrigin(), b.GetOrigin())
                and np.allclose(a.GetSpacing(), b.GetSpacing()))
    if a.IsA("vtkPointSet") and not np.array_equal(vtk_to_numpy(a.GetPoints().GetData()),
                                                   vtk_to_numpy(b.GetPoints().GetData())):
        return False
    if a.IsA("vtkUnstructuredGrid"):
        import pyvista as pv

        wa, wb = pv.wrap(a), pv.wrap(b)
        return bool(np.array_equal(wa.cell_connectivity, wb.cell_connectivity)
                    and np.array_equal(wa.cell_offsets, wb.cell_offsets) and np.array_equal(wa.celltypes, wb.celltypes))
    return True


def fields_on_shared_meshes(leaves: Sequence[tuple[str, Any]]) -> Any:
    """Blocks ``(name, data set)`` as one data object: blocks on one mesh become one data set with all their arrays
    (a name already taken gets `` (block)`` after it); several meshes a multiblock of them."""
    from volviz.io.vtk_lazy import vtk

    meshes: list[tuple[Any, set[str], set[str]]] = []
    for name, leaf in leaves:
        for mesh, point_names, cell_names in meshes:
            if _same_mesh(mesh, leaf):
                break
        else:
            mesh = leaf.NewInstance()
            mesh.ShallowCopy(leaf)
            meshes.append((mesh, {a.GetName() for a in _arrays(mesh.GetPointData())},
                           {a.GetName() for a in _arrays(mesh.GetCellData())}))
            continue
        for source, target, taken in ((leaf.GetPointData(), mesh.GetPointData(), point_names),
                                      (leaf.GetCellData(), mesh.GetCellData(), cell_names)):
            for array in _arrays(source):
                if array.GetName() in taken:
                    copy = array.NewInstance()
                    copy.ShallowCopy(array)
                    copy.SetName(f"{array.GetName()} ({name.rsplit('/', 1)[-1]})")
                    array = copy
                taken.add(array.GetName())
                target.AddArray(array)
    if len(meshes) == 1:
        return meshes[0][0]
    out = vtk.vtkMultiBlockDataSet()
    for i, (mesh, _, _) in enumerate(meshes):
        out.SetBlock(i, mesh)
    return out


def shown_leaves(leaves: Sequence[tuple[str, Any]], temporal: Sequence[str]) -> list[tuple[str, Any]]:
    """The blocks shown by default: those inside the temporal collections when there are any, else all."""
    inside = [(name, leaf) for name, leaf in leaves if name.split("/", 1)[0] in temporal]
    return inside or list(leaves)
