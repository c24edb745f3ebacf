"""volviz reader plugin: the formats a ParaView user brings, opened by VTK's own readers.

Registered through the ``volviz.readers`` entry point (``volviz_vtk_readers.specs:SPECS``); ``volviz.io.read``
dispatches to the loaders in ``volviz_vtk_readers.readers``. What each format gives by default, and why:

- Exodus II (.e .ex2 .exo .g): every element block merged into one mesh, with every nodal variable (point data) and
  element variable (cell data). Element blocks are parts of one mesh sharing its nodes, and ParaView loads them all;
  node and side sets stay off (ParaView's default too). ``blocks=["Unnamed block ID: 1", ...]`` picks blocks.
- OpenFOAM (a ``.foam`` file in the case folder, or the folder holding ``system/controlDict``): the internal mesh only
  -- ParaView's default; the patches are boundary surfaces, and merging them with the volume cells would mix
  dimensions -- with every field as cell data and, with VTK's cell-to-point on, as point data. Time 0 is kept.
  ``blocks=["internalMesh", "patch/movingWall"]`` adds patches.
- CGNS (.cgns, ADF or HDF5): every zone of every base merged; boundary patches off. A single zone (``blocks=``)
  keeps its structured grid. FlowSolution arrays come as they are stored (cell data in cell-centred solutions).
- EnSight (.case): every part merged, every variable.
- netCDF with CF conventions (.nc): one grid, not blocks: every variable on the first set of dimensions the reader
  finds (``dimensions="(lat, lon)"`` picks another). Fill values become NaN (land in an ocean field is then
  transparent, not 1e20). Latitude/longitude grids are placed on the unit sphere (SphericalCoordinates on), as in
  ParaView, whose netCDF CF reader has it on by default: a ParaView user sees the globe, and curvilinear ocean grids
  (tripolar, rotated poles) are only drawn without folds that way. ``spherical=False`` gives the flat lon/lat plane.
- Tecplot ASCII (.dat .plt .tec with a Tecplot header): every zone merged. Binary Tecplot is refused with a hint.
- AVS UCD (.inp .ucd, ASCII or binary; told from Abaqus .inp by content): the mesh with every component.
- Fluent (.cas with its .dat beside it, or the .dat): every cell zone merged with every cell field.
- Fluent CFF (.cas.h5 with its .dat.h5 beside it, or the .dat.h5; HDF5): the same through vtkFLUENTCFFReader
  (``volviz_vtk_readers.fluentcff``); an .h5 of this kind under any name is sent there by ``volviz.io.hdf5kind``.
- VTK multiblock (.vtm .vtpd): every block merged (what ParaView shows on open); ``blocks=`` picks some.
- VTK parallel XML (.pvtu .pvti .pvts .pvtr .pvtp): the pieces joined into one data set by VTK's reader.
- XDMF (.xdmf .xmf, versions 2 and 3; FEniCS / dolfinx, meshio, HPC codes): the temporal collections when the file
  has any (dolfinx writes the bare mesh as a grid of its own beside them), else every grid; blocks on one mesh are
  fields of it (one data set with every block's arrays), as in ``volviz_vtk_readers.xdmf``.

Files with several time steps become a ``volviz.model.TimeSeries``; ``list_blocks(path)`` lists block names.
"""
from volviz_vtk_readers.specs import SPECS

__all__ = ["SPECS", "list_blocks"]


def list_blocks(path):
    """The names ``blocks=`` takes for this file (``readers.list_blocks``), found by VTK's reader in the isolated
    reader process like a read (``volviz.io.isolated``), unless isolation is off."""
    from volviz.io import isolated
    from volviz.io.registry import spec_of

    if isolated.isolation_enabled():
        return isolated.names_isolated(spec_of(path), path, "volviz_vtk_readers.readers:list_blocks")
    from volviz_vtk_readers.readers import list_blocks as _list_blocks  # imports VTK: only when it is used

    return _list_blocks(path)
