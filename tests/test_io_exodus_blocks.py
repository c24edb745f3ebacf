"""An Exodus II file whose element blocks do not all carry the same element variables (Exodus's truth table) reads
every block, each variable on the blocks that define it and NaN on the others, as VTK's vtkExodusIIReader gives them
block by block. The file is written here as Exodus's classic netCDF layout with SciPy's netCDF writer."""
from __future__ import annotations

import warnings

import numpy as np
from scipy.io import netcdf_file
from vtk.util.numpy_support import vtk_to_numpy

import volviz.io as vio
from volviz.model.arrays import default_array

BLOCKS = (3, 2, 4)                      # hexahedra per element block, in a row along x
TABLE = ((1, 1), (1, 0), (0, 1))        # which block carries stress, damage
NAMES = ("stress", "damage")


def _value(block: int, var: int, step: int, n: int) -> np.ndarray:
    return 100.0 * block + 10 * var + np.arange(n) + step


def _corner(x: int, y: int, z: int) -> int:
    return x * 4 + y * 2 + z + 1


def write_exodus(path) -> None:
    total = sum(BLOCKS)
    points = np.array([[x, y, z] for x in range(total + 1) for y in (0, 1) for z in (0, 1)], float)
    f = netcdf_file(path, "w", version=2)
    f.api_version = f.version = np.float32(8.03)
    f.floating_point_word_size, f.file_size, f.title = np.int32(8), np.int32(1), b"blocks with different variables"
    f.createDimension("time_step", None)
    for name, size in (("len_string", 33), ("len_name", 33), ("len_line", 81), ("four", 4), ("num_dim", 3),
                       ("num_nodes", len(points)), ("num_elem", total), ("num_el_blk", len(BLOCKS)),
                       ("num_elem_var", len(NAMES))):
        f.createDimension(name, size)
    f.createVariable("time_whole", "d", ("time_step",))[:2] = [0.0, 1.0]
    for i, axis in enumerate("xyz"):
        f.createVariable("coord" + axis, "d", ("num_nodes",))[:] = points[:, i]
    f.createVariable("eb_status", "i", ("num_el_blk",))[:] = 1
    ids = f.createVariable("eb_prop1", "i", ("num_el_blk",))
    ids.name, ids[:] = b"ID", np.arange(1, len(BLOCKS) + 1) * 10
    names = f.createVariable("name_elem_var", "c", ("num_elem_var", "len_name"))
    for i, name in enumerate(NAMES):
        names[i, :] = np.frombuffer(name.encode().ljust(33, b"\0"), "S1")
    f.createVariable("elem_var_tab", "i", ("num_el_blk", "num_elem_var"))[:] = np.array(TABLE)
    start = 0
    for b, n in enumerate(BLOCKS, 1):
        f.createDimension(f"num_el_in_blk{b}", n)
        f.createDimension(f"num_nod_per_el{b}", 8)
        conn = f.createVariable(f"connect{b}", "i", (f"num_el_in_blk{b}", f"num_nod_per_el{b}"))
        conn.elem_type = b"HEX8"
        conn[:] = [[_corner(e, 0, 0), _corner(e + 1, 0, 0), _corner(e + 1, 1, 0), _corner(e, 1, 0), _corner(e, 0, 1),
                    _corner(e + 1, 0, 1), _corner(e + 1, 1, 1), _corner(e, 1, 1)] for e in range(start, start + n)]
        for v in range(len(NAMES)):
            if TABLE[b - 1][v]:
                values = f.createVariable(f"vals_elem_var{v + 1}eb{b}", "d", ("time_step", f"num_el_in_blk{b}"))
                for step in range(2):
                    values[step, :] = _value(b, v, step, n)
        start += n
    f.close()


def _vtk_blocks(path, step: int):
    import vtk

    reader = vtk.vtkExodusIIReader()
    reader.SetFileName(str(path))
    reader.UpdateInformation()
    for i in range(reader.GetNumberOfObjectArrays(reader.ELEM_BLOCK)):
        reader.SetObjectArrayStatus(reader.ELEM_BLOCK, i, 1)
    reader.UpdateTimeStep(float(step))
    out = reader.GetOutput().GetBlock(0)
    return [out.GetBlock(i) for i in range(out.GetNumberOfBlocks())]


def test_every_block_reads_with_each_variable_where_it_is_defined(tmp_path):
    path = tmp_path / "mixed.exo"
    write_exodus(path)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        series = vio.read(path)
    assert [str(w.message) for w in caught] == [f"{path}: damage (cell), stress (cell): defined on some of its 3 "
                                                "blocks only; NaN (not drawn) on the others"]
    assert vio.read(path, allow_nonfinite=False).n_steps == 2   # the NaN put there are not the file's
    assert series.n_steps == 2
    for step in range(2):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            mesh = series.frame(step)
        blocks = _vtk_blocks(path, step)
        assert (mesh.n_points, mesh.n_cells) == (sum(b.GetNumberOfPoints() for b in blocks), 9) == (48, 9)
        for v, name in enumerate(NAMES):
            expected = []
            for b, block in enumerate(blocks, 1):
                arr = block.GetCellData().GetArray(name)
                assert (arr is not None) == bool(TABLE[b - 1][v])
                expected.append(vtk_to_numpy(arr) if arr is not None else np.full(BLOCKS[b - 1], np.nan))
                if arr is not None:
                    np.testing.assert_array_equal(vtk_to_numpy(arr), _value(b, v, step, BLOCKS[b - 1]))
            np.testing.assert_array_equal(mesh.cell_data[name], np.concatenate(expected))
        np.testing.assert_array_equal(mesh.cell_data["ObjectId"], np.repeat([10, 20, 30], BLOCKS))
    assert default_array(mesh) in NAMES
