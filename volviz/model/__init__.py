"""Dataset types shared by readers, renderers and the app."""
from volviz.model.datasets import (
    CELL_SIZES,
    VTK_HEXAHEDRON,
    VTK_PYRAMID,
    VTK_QUAD,
    VTK_TETRA,
    VTK_TRIANGLE,
    VTK_VERTEX,
    VTK_WEDGE,
    CurvilinearGrid,
    Dataset,
    Image2D,
    RegularVolume,
    TetMesh,
    TimeSeries,
    UnstructuredMesh,
    vec3,
)

__all__ = [
    "CELL_SIZES", "VTK_HEXAHEDRON", "VTK_PYRAMID", "VTK_QUAD", "VTK_TETRA", "VTK_TRIANGLE", "VTK_VERTEX",
    "VTK_WEDGE",
    "CurvilinearGrid", "Dataset", "Image2D", "RegularVolume", "TetMesh", "TimeSeries", "UnstructuredMesh",
    "vec3",
]
