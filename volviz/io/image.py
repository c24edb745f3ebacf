"""Ordinary raster images (PNG, JPEG, TIFF, BMP) -> Image2D (e.g. the sky/clouds.jpeg photo); multi-page TIFF
stacks (microscopy) -> a volume through ``volviz.io.tiffstack``; single-band GeoTIFFs -> heights in metres through
``volviz.io.elevation``; TIFFs of 32-bit samples as stored.

The header is read first (Pillow); images of more than ``MAX_PIXELS`` pixels are refused before decoding (a small
compressed file can describe a gigantic image). PNG, TIFF and BMP are decoded by Pillow; JPEG by VTK's
``vtkJPEGReader`` (the same libjpeg-turbo, the same pixels), because libjpeg reports a damaged stream (a premature
end of the data, an image taller than its data) only as a warning, which Pillow ignores and fills the missing rows
with grey, while VTK's reader treats it as the error it is. The reader runs in the isolated reader process
(``volviz.io.isolated``): these decoders are native code.
"""
from __future__ import annotations

import numpy as np

from volviz.io._checks import check_file, open_file, read_bytes
from volviz.io.elevation import geotiff_tags, read_geotiff_dem
from volviz.io.errors import PathLike, ReadError
from volviz.io.tiffstack import is_tiff, read_tiff_stack
from volviz.io.vtk_lazy import vtk
from volviz.io.vtkfiles import _run
from volviz.model import Image2D, RegularVolume, TimeSeries

EXTENSIONS = (".png", ".jpg", ".jpeg", ".tif", ".tiff", ".bmp")
MAX_PIXELS = 1 << 28


def read_image(path: PathLike) -> Image2D | RegularVolume | TimeSeries:
    """Read a PNG/JPEG/TIFF/BMP into Image2D: (rows, cols) grey or (rows, cols, 3|4) color, row 0 at the top; a
    TIFF whose pages make a stack becomes a volume (``volviz.io.tiffstack``)."""
    # heavy: Pillow, loaded only when an image file is read
    from PIL import Image, UnidentifiedImageError

    check_file(path)
    if is_tiff(read_bytes(path, 4)):
        stack = read_tiff_stack(path)
        if stack is not None:
            return stack

        tags = geotiff_tags(path)
        if tags is not None:
            return read_geotiff_dem(path, tags)
    with open_file(path) as fh:
        try:
            with Image.open(fh) as im:
                width, height = im.size
                if width <= 0 or height <= 0:
                    raise ReadError(path, f"image size {width}x{height} must be positive")
                if width * height > MAX_PIXELS:
                    raise ReadError(path, f"image claims {width}x{height} pixels, more than the limit of {MAX_PIXELS}")
                if im.format == "JPEG" and im.mode in ("L", "RGB"):
                    data = _jpeg_pixels(path)
                elif im.mode in ("F", "I") and im.format == "TIFF":   # 32-bit samples: as stored, not as color
                    data = _tiff_page(path)
                else:
                    if im.mode not in ("L", "I;16", "I;16B", "RGB", "RGBA"):
                        im = im.convert("RGBA" if "A" in im.getbands() else "RGB")
                    data = np.array(im)
        except ReadError:
            raise
        except UnidentifiedImageError:
            raise ReadError(path, "not a readable image: its first bytes are not those of a PNG, JPEG, TIFF or BMP "
                                  "image") from None
        except OSError as exc:
            if "truncated" in str(exc).lower():
                raise ReadError(path, "not a readable image: its pixel data ends before the image does (the file is "
                                      "truncated)") from None
            raise ReadError(path, f"not a readable image: its pixel data cannot be decoded ({str(exc)[:200]})") \
                from None
        except (ValueError, SyntaxError, Image.DecompressionBombError) as exc:
            raise ReadError(path, f"not a readable image ({type(exc).__name__}: {str(exc)[:200]})") from None
    maxval = 65535 if data.dtype == np.uint16 else 255
    return Image2D(data, maxval=maxval, source=str(path))


def _tiff_page(path: PathLike) -> np.ndarray:
    """The first page of a TIFF of 32-bit samples (float heights, counts) as stored, by tifffile."""
    # heavy: tifffile (about 15 modules), loaded only when a TIFF is read
    import tifffile

    try:
        with tifffile.TiffFile(str(path)) as tif:
            return tif.pages.first.asarray()
    except (tifffile.TiffFileError, ValueError, OSError, EOFError) as exc:
        raise ReadError(path, f"its samples could not be read ({exc})") from None


def _jpeg_pixels(path: PathLike) -> np.ndarray:
    """A JPEG's pixels by ``vtkJPEGReader`` (libjpeg's warnings are errors there): (rows, cols) grey or
    (rows, cols, 3), row 0 at the top."""
    # heavy: VTK's numpy_support (vtkCommonCore), loaded only when VTK reads the image
    from vtkmodules.util.numpy_support import vtk_to_numpy

    reader = vtk.vtkJPEGReader()
    reader.SetFileName(str(path))
    out = _run(path, reader)
    width, height, _ = out.GetDimensions()
    scalars = out.GetPointData().GetScalars()
    if scalars is None or width * height == 0:
        raise ReadError(path, "the JPEG decoder returned no pixels: the file is damaged")
    pixels = vtk_to_numpy(scalars).reshape(height, width, -1)[::-1]
    return np.ascontiguousarray(pixels[..., 0] if pixels.shape[2] == 1 else pixels)
