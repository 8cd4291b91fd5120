# SPDX-License-Identifier: Apache-2.0
"""to_uint8: a render as 8-bit sRGB RGBA for Pillow, imageio or matplotlib, as umbra's PNG
writer (io/image.cpp) encodes it; for a package built without OpenImageIO (the wheel), where
Context.write_image refuses, and for notebooks."""

import numpy as np


def to_uint8(rgba):
    """Premultiplied linear RGBA floats, (..., 4), to un-premultiplied 8-bit sRGB RGBA: colour
    divided by alpha (where alpha > 0), clamped to [0, 1], sRGB-encoded (the exact piecewise
    curve), rounded; alpha clamped and rounded.
    ``PIL.Image.fromarray(umbra.to_uint8(img)).save("x.png")`` writes the PNG umbra-render would."""
    rgba = np.asarray(rgba, dtype=np.float32)
    if rgba.shape[-1:] != (4,):
        raise ValueError(f"umbra.to_uint8: shape {rgba.shape} does not end in 4 (RGBA)")
    a = rgba[..., 3:4]
    with np.errstate(divide="ignore", invalid="ignore"):
        rgb = np.where(a > 0, rgba[..., :3] / a, rgba[..., :3])
    rgb = np.nan_to_num(rgb, nan=0.0).clip(0.0, 1.0)
    a = np.nan_to_num(a, nan=0.0).clip(0.0, 1.0)
    srgb = np.where(rgb <= np.float32(0.0031308), np.float32(12.92) * rgb,
                    np.float32(1.055) * rgb ** np.float32(1 / 2.4) - np.float32(0.055))
    out = np.concatenate([srgb, a], axis=-1).clip(0.0, 1.0) * np.float32(255)
    return np.rint(out).astype(np.uint8)
