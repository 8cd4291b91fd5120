# SPDX-License-Identifier: Apache-2.0
"""Rendered frames at the notebook: 8-bit sRGB conversion, a small image type that shows itself
(IPython's ``_repr_png_``), and readable reprs for the C structs bound as plain records.

The conversion is the one ``Context.write_image`` applies for ``.png`` (io/image.cpp): colour
un-premultiplied by alpha, clamped to [0, 1] (NaN to 0), encoded with the exact piecewise sRGB
curve, rounded to the nearest of 255 levels; alpha clamped and rounded. The PNG is written here
with the standard library's zlib, so the package needs nothing beyond NumPy to show a frame.
"""

import struct
import sys
import zlib

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["Image", "show", "to_srgb8"]


def _rgba_array(rgba: ArrayLike, what: str) -> np.ndarray:
    a = np.asarray(rgba)
    if a.ndim != 3 or a.shape[2] != 4:
        raise ValueError(f"{what}: shape {a.shape} is not (height, width, 4)")
    if a.shape[0] == 0 or a.shape[1] == 0:
        raise ValueError(f"{what}: shape {a.shape} has no pixels")
    if not np.issubdtype(a.dtype, np.floating):
        raise ValueError(f"{what}: dtype {a.dtype} is not a float type (premultiplied RGBA)")
    return a


def _clamp01(v):
    return np.clip(np.nan_to_num(v, nan=0.0, posinf=1.0, neginf=0.0), 0.0, 1.0)


def to_srgb8(rgba: ArrayLike) -> np.ndarray:
    """(H, W, 4) premultiplied linear RGBA floats (what ``Renderer.render`` returns) as a new
    (H, W, 4) uint8 array of un-premultiplied sRGB-encoded RGBA, as ``Context.write_image`` writes
    a PNG."""
    a = _rgba_array(rgba, "umbra.to_srgb8: rgba").astype(np.float64)
    alpha = a[..., 3:4]
    colour = np.divide(a[..., :3], alpha, out=a[..., :3].copy(), where=alpha > 0.0)
    colour = _clamp01(colour)
    encoded = np.where(
        colour <= 0.0031308, 12.92 * colour, 1.055 * np.power(colour, 1.0 / 2.4) - 0.055
    )
    out = np.empty(a.shape, np.uint8)
    out[..., :3] = np.rint(_clamp01(encoded) * 255.0)
    out[..., 3] = np.rint(_clamp01(alpha[..., 0]) * 255.0)
    return out


def _png_chunk(kind: bytes, data: bytes) -> bytes:
    body = kind + data
    return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body) & 0xFFFFFFFF)


def _png_bytes(rgba8: np.ndarray) -> bytes:
    h, w, _ = rgba8.shape
    # Each row: filter type 0 (none), then the row's RGBA bytes.
    rows = np.concatenate([np.zeros((h, 1), np.uint8), rgba8.reshape(h, 4 * w)], axis=1)
    return (
        b"\x89PNG\r\n\x1a\n"
        + _png_chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 6, 0, 0, 0))
        + _png_chunk(b"sRGB", b"\x00")
        + _png_chunk(b"IDAT", zlib.compress(rows.tobytes(), 6))
        + _png_chunk(b"IEND", b"")
    )


class Image:
    """A rendered frame that shows itself in a notebook (Jupyter, IPython) as a PNG.

    ``umbra.Image(renderer.render(w, h))``: wraps the (H, W, 4) premultiplied linear float RGBA
    array without copying it (``numpy.asarray(image)`` gives it back); ``to_srgb8()`` and
    ``png()`` convert it as ``Context.write_image`` does for ``.png``.
    """

    __slots__ = ("rgba",)

    def __init__(self, rgba: ArrayLike) -> None:
        self.rgba = _rgba_array(rgba, "umbra.Image: rgba")

    @property
    def width(self) -> int:
        return self.rgba.shape[1]

    @property
    def height(self) -> int:
        return self.rgba.shape[0]

    def to_srgb8(self) -> np.ndarray:
        """The (H, W, 4) uint8 sRGB RGBA pixels (umbra.to_srgb8)."""
        return to_srgb8(self.rgba)

    def png(self) -> bytes:
        """The image as the bytes of a PNG file (8-bit sRGB RGBA)."""
        return _png_bytes(self.to_srgb8())

    def _repr_png_(self) -> bytes:
        return self.png()

    def __array__(self, dtype=None, copy=None):
        if copy:
            return np.array(self.rgba, dtype=dtype)
        return self.rgba if dtype is None else self.rgba.astype(dtype, copy=False)

    def __repr__(self) -> str:
        return f"umbra.Image({self.width} x {self.height}, {self.rgba.dtype} premultiplied RGBA)"


def show(rgba: ArrayLike) -> None:
    """Shows a rendered frame in the running notebook (IPython.display.display of an
    :class:`Image`) and returns None; outside IPython raises RuntimeError (use
    ``Context.write_image`` there)."""
    image = Image(rgba)
    ipython = sys.modules.get("IPython")
    shell = ipython.get_ipython() if ipython is not None else None
    if shell is None:
        raise RuntimeError(
            "umbra.show: no IPython shell is running; in a script write the frame with "
            "Context.write_image(path, rgba), or make the PNG bytes with umbra.Image(rgba).png()"
        )
    from IPython.display import display

    display(image)


def _short(v):
    if isinstance(v, float):
        return f"{v:.6g}"
    if isinstance(v, tuple):
        inner = ", ".join(_short(x) for x in v)
        return f"({inner},)" if len(v) == 1 else f"({inner})"
    return repr(v)


def _fields_repr(self):
    """'umbra.Name(field=value, ...)' over the read-only properties the binding defines, in their
    order, so that a field added to the C struct and bound shows up too."""
    cls = type(self)
    parts = [
        f"{name}={_short(getattr(self, name))}"
        for name, attr in vars(cls).items()
        if isinstance(attr, property) and not name.startswith("_")
    ]
    return f"umbra.{cls.__name__}({', '.join(parts)})"


def install_reprs(*classes):
    for cls in classes:
        cls.__repr__ = _fields_repr
