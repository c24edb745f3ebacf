"""Any thread: the tetrahedral meshes the pre-integrated projected tetrahedra draw (Röttger et al. §3: cells split
into tetrahedra, their adjacency for the visibility sort), cut exactly by the scene's clipping, and the render
options as the PT renderer's keywords."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Optional

import numpy as np

from volviz.model.datasets import TetMesh
from volviz.unstructured import index_buffer, probe
from volviz.unstructured.boundary_pairs import inner_boundary
from volviz.unstructured.tetrahedralize import tetrahedralize
from volviz.unstructured.topology import cell_ranges, topology

if TYPE_CHECKING:   # type-only imports for the signatures
    from volviz.model.clip import ClipSettings


def pt_mesh(dataset: object) -> TetMesh:
    """Any thread: the tetrahedral mesh a PT volume draws for ``dataset``, with its topology built (cached on it) and
    the kernels the GUI thread calls first for it loaded (``_load_gui_kernels``)."""
    mesh = dataset if isinstance(dataset, TetMesh) else tetrahedralize(dataset, getattr(dataset, "active", None))
    _with_adjacency(mesh)
    _load_gui_kernels()
    return mesh


def _load_gui_kernels() -> None:
    """Load from Numba's cache, here on the caller's thread, the kernels that the GUI thread calls first for a PT
    volume: a kernel's first call in a process holds the GIL while it loads (issue #28). They are the GPU volume's
    static index buffer, filled as the volume is installed, and the probe under the cursor."""
    index_buffer.load_kernels(np.empty(0, np.int32), np.empty(0, bool))
    probe.load_kernels()


def _with_adjacency(mesh: TetMesh) -> None:
    """Build ``mesh``'s topology with what its first visibility order reads (``volviz.unstructured.sort``: the face
    adjacency, the boundary faces off the convex hull) and the cells' scalar ranges its view culls by
    (``visible_cells``, as a GPU PT volume is made), here on the caller's thread instead of on the GUI thread, which
    makes the view and draws its first frame."""
    topo = topology(mesh)
    cell_ranges(mesh)
    try:
        topo.back_face   # (and the adjacency it is made from)
    except ValueError:   # not manifold: the sort says so, where it is used, as before
        return
    inner_boundary(topo)


def cut_tetmesh(mesh: TetMesh, clip: ClipSettings) -> Optional[TetMesh]:
    """Any thread: ``mesh`` cut exactly by ``clip`` (``volviz.iso.clip.clip_tetmesh``) with its topology built; None
    when the clipping removes all of it."""
    from volviz.iso.clip import clip_tetmesh   # the isosurface package's modules: only for a clipped mesh (start-up)

    try:
        cut = clip_tetmesh(mesh, clip)
    except ValueError:  # everything clipped away
        return None
    _with_adjacency(cut)
    return cut


def pt_options(options: dict[str, object]) -> dict[str, object]:
    """Render settings -> keywords of ``volviz.unstructured.render``: sort ("mpvo", "centroid", "power"), table
    ("auto" by optical depth, "3d", or "separable-N" with a color polynomial of degree N) and its resolution."""
    out: dict[str, Any] = {}
    sort = options.get("sort")
    if sort in ("mpvo", "centroid", "power"):
        out["sort"] = sort
    table = str(options.get("table", "auto"))
    resolution = options.get("table_resolution")
    if table == "3d":
        out["lookup"] = "3d"
    elif table.startswith("separable-") and table[len("separable-"):] in ("1", "2", "4"):
        out.update(lookup="separable", degree=int(table[len("separable-"):]))
    if table != "auto" and isinstance(resolution, int) and 16 <= resolution <= 1024:
        out["n_s"] = resolution
    return out
