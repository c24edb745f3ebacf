"""What a GPU PT fragment evaluates a ray segment with (``volviz.render.gl_pt``; Roettger §8.4, §9.1, §8.8-8.14):
the fragment shader made for one kind of evaluation and number of clipping planes (``PT_KIND``, ``PT_CLIPS``:
compiled in, not switched, since llvmpipe pays for every branch), the resolve's shader variant, the table of each
kind packed as float32 texels (3D pre-integration table, separable table layers, isosurface rows, pre-classified TF
rows), and its uniforms."""
from __future__ import annotations

from typing import TYPE_CHECKING, Iterable, Union, cast

import numpy as np

from volviz.render.gl import shader_source, table_texture, with_defines

if TYPE_CHECKING:   # type-only: the tables a PT pass evaluates, VTK's classes reached through the facade at run time
    from volviz.optics.isosurface import IsoTable
    from volviz.optics.separable import SeparableTable
    from volviz.optics.table3d import Table3D
    from volviz.render.vtk_facade import vtkOpenGLRenderWindow, vtkShaderProgram, vtkTextureObject
    from volviz.unstructured.render import Preclassified

    #: a table of any kind ``gl_pt`` builds (``GLPTVolume._build_table``), told apart by its attributes
    PTTable = Union[IsoTable, Preclassified, Table3D, SeparableTable]

__all__ = ["AMBIENT", "KINDS", "pt_shader", "resolve_shader", "set_table_uniforms", "table_texels",
           "upload_table"]

AMBIENT = 0.3                          # smooth isosurfaces: vertex_shade's default ambient term
KINDS = {"3d": 0, "separable": 1, "iso": 2, "pre": 3}   # PT_KIND of each segment evaluation


def pt_shader(name: str, smooth: bool, kind: int = 0, clips: int = 0) -> str:
    """A pass shader for one kind of segment evaluation (``PT_KIND``: 0 3D table, 1 separable, 2 isosurfaces, 3
    pre-classified) and ``clips`` user clipping planes (``PT_CLIPS``), with ``PT_SMOOTH`` defined for smooth
    isosurfaces."""
    head = f"#define PT_KIND {kind}\n#define PT_CLIPS {clips}\n" + ("#define PT_SMOOTH\n" if smooth else "")
    return with_defines(shader_source(name), head)


def resolve_shader(upsample: bool) -> str:
    """The resolve's fragment shader: one texel per pixel, or (``upsample``, an interactive frame drawn smaller) the
    target sampled bilinearly at each pixel's centre (``PT_UPSAMPLE``)."""
    return with_defines(shader_source("pt_resolve_fs.glsl"), "#define PT_UPSAMPLE\n" if upsample else "")


def table_texels(table: PTTable) -> tuple[np.ndarray, bool]:
    """(texels (nz, ny, nx, 4) float32, layered) of a table of any kind: isosurfaces (rows: value and opacity, front
    colors, back colors; one texel per surface in value order), pre-classified (rows: kappa's color and rho; the
    scalar), the 3D table (x = l, y = s_b, z = s_f) or the separable one (x = s_f, y = s_b, a layer per polynomial
    term in l: ``layered``, a 2D texture array)."""
    if hasattr(table, "isosurfaces"):
        isos = sorted(table.isosurfaces, key=lambda i: i.value)
        data = np.zeros((1, 3, len(isos), 4), np.float32)
        for k, i in enumerate(isos):
            data[0, :, k, :3] = [(i.value, i.opacity, 0.0), i.color, i.color if i.back_color is None else i.back_color]
        return data, False
    if hasattr(table, "preclassified_tf"):
        tf = table.preclassified_tf
        data = np.zeros((1, 2, len(tf.scalars), 4), np.float32)
        data[0, 0, :, :3] = tf.colors
        data[0, 0, :, 3] = tf.extinction
        data[0, 1, :, 0] = tf.scalars
        return data, False
    if hasattr(table, "rgba"):
        return np.ascontiguousarray(table.rgba, dtype=np.float32), False
    n, deg = table.n_s, table.degree
    layers = np.zeros((deg + 1, n, n, 4), np.float32)
    d = table.data.transpose(1, 0, 2)                       # (s_b, s_f, channels)
    layers[0] = d[..., 0:4]
    for i in range(1, deg + 1):
        layers[i, ..., :3] = d[..., 1 + 3 * i:4 + 3 * i]
    return np.ascontiguousarray(layers), True


def upload_table(ren_win: vtkOpenGLRenderWindow, table: PTTable) -> vtkTextureObject:
    """The texture of ``table`` (``table_texels``) in ``ren_win``'s context."""
    data, layered = table_texels(table)
    return table_texture(ren_win, data, layered)


def set_table_uniforms(program: vtkShaderProgram, table: PTTable, smooth: bool, light: Iterable[float]) -> None:
    """The uniforms of ``table``'s kind: row counts (isosurfaces, pre-classified), the thickening and, for
    ``smooth`` isosurfaces, the headlight direction ``light`` and the ambient term; the tables' axes otherwise."""
    # each kind is told apart by an attribute as in table_texels; mypy's hasattr keeps the other kinds in the union,
    # so the branch names its kind (a cast: nothing checked or converted at run time)
    if hasattr(table, "isosurfaces"):
        iso = cast("IsoTable", table)
        program.SetUniformi("rowCount", len(iso.isosurfaces))
        program.SetUniformf("isoThicken", float(iso.thicken))
        if smooth:
            program.SetUniform3f("shadeLight", [float(x) for x in light])
            program.SetUniformf("shadeAmbient", AMBIENT)
        return
    if hasattr(table, "preclassified_tf"):
        program.SetUniformi("rowCount", len(table.preclassified_tf.scalars))
        return
    program.SetUniform4f("tableAxis", [float(table.s_lo), float(1.0 / table.ds), float(table.n_s), 0.0])
    if hasattr(table, "rgba"):
        table3d = cast("Table3D", table)
        program.SetUniform4f("tableLength", [float(1.0 / table3d.dl), float(table3d.n_l), 0.0, 0.0])
    else:
        program.SetUniform4f("tableLength", [float(1.0 / table.l_max), 0.0, float(table.degree), 0.0])
        program.SetUniform3f("kappaMax", [float(x) for x in table.kappa_max])
