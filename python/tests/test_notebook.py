# SPDX-License-Identifier: Apache-2.0
"""Python at the notebook (#28 item 6): a rendered frame shows itself (umbra.Image's _repr_png_),
converts to 8-bit sRGB exactly as Context.write_image writes a PNG (umbra.to_srgb8), and
VolumeInfo and RenderStats print their fields."""

import io
import sys
import types

import numpy as np
import pytest

import umbra


@pytest.fixture(scope="module")
def frame(ctx):
    scene = umbra.Scene(ctx, "spheres", 32)
    with scene.renderer() as r:
        return r.render(40, 30, technique="cssm"), r.stats


def test_to_srgb8_known_values():
    """Un-premultiplied, clamped, the exact sRGB curve, rounded: linear 0.5 is 187.5 -> 188,
    0.0031308 sits on the curve's knee (12.92 x: 10.3 -> 10), alpha 0 keeps its colour 0,
    as io/image.cpp's write_png does."""
    rgba = np.array(
        [[[0.5, 0.5, 0.5, 1.0],         # linear 0.5
          [0.125, 0.0, 0.25, 0.5],      # premultiplied by 0.5: colour 0.25, 0, 0.5
          [0.0031308, 1.0, 2.0, 1.0],   # knee, white, over-white clamps
          [0.0, 0.0, 0.0, 0.0]],        # transparent
         [[np.nan, -1.0, np.inf, 1.0],  # NaN -> 0, negative -> 0, inf -> 1
          [0.2, 0.2, 0.2, 1.5],         # alpha above 1: colour 0.2 / 1.5, alpha clamps to 255
          [1e-6, 1e-6, 1e-6, 1.0],
          [0.21586, 0.21586, 0.21586, 1.0]]],  # sRGB 128 / 255
        np.float32)
    got = umbra.to_srgb8(rgba)
    assert got.dtype == np.uint8 and got.shape == (2, 4, 4)
    assert got[0, 0].tolist() == [188, 188, 188, 255]
    assert got[0, 1].tolist() == [137, 0, 188, 128]
    assert got[0, 2].tolist() == [10, 255, 255, 255]
    assert got[0, 3].tolist() == [0, 0, 0, 0]
    assert got[1, 0].tolist() == [0, 0, 255, 255]
    assert got[1, 1].tolist() == [102, 102, 102, 255]
    assert got[1, 2].tolist() == [0, 0, 0, 255]
    assert got[1, 3].tolist() == [128, 128, 128, 255]


def test_image_shows_itself_as_a_png(frame):
    """_repr_png_ is what Jupyter displays: a PNG whose pixels are to_srgb8's."""
    PIL = pytest.importorskip("PIL.Image")
    img, _ = frame
    image = umbra.Image(img)
    png = image._repr_png_()
    assert png[:8] == b"\x89PNG\r\n\x1a\n"
    decoded = PIL.open(io.BytesIO(png))
    assert decoded.mode == "RGBA" and decoded.size == (40, 30)
    assert np.array_equal(np.asarray(decoded), umbra.to_srgb8(img))
    assert (image.width, image.height) == (40, 30)
    assert np.shares_memory(np.asarray(image), img)   # no copy of the frame
    assert repr(image) == "umbra.Image(40 x 30, float32 premultiplied RGBA)"
    # render's own return value is unchanged: a plain (H, W, 4) float32 array.
    assert type(img) is np.ndarray and img.dtype == np.float32 and img.shape == (30, 40, 4)


def test_image_refuses_what_is_not_rgba():
    with pytest.raises(ValueError, match=r"shape \(4, 4, 3\) is not \(height, width, 4\)"):
        umbra.Image(np.zeros((4, 4, 3), np.float32))
    with pytest.raises(ValueError, match="dtype uint8 is not a float type"):
        umbra.to_srgb8(np.zeros((4, 4, 4), np.uint8))
    with pytest.raises(ValueError, match="has no pixels"):
        umbra.to_srgb8(np.zeros((0, 4, 4), np.float32))


def test_show_displays_in_ipython_and_refuses_elsewhere(frame, monkeypatch):
    img, _ = frame
    monkeypatch.delitem(sys.modules, "IPython", raising=False)
    with pytest.raises(RuntimeError, match="no IPython shell is running"):
        umbra.show(img)
    shown = []
    ipython = types.ModuleType("IPython")
    ipython.get_ipython = lambda: object()
    display = types.ModuleType("IPython.display")
    display.display = shown.append
    ipython.display = display
    monkeypatch.setitem(sys.modules, "IPython", ipython)
    monkeypatch.setitem(sys.modules, "IPython.display", display)
    assert umbra.show(img) is None
    assert len(shown) == 1 and isinstance(shown[0], umbra.Image)
    assert shown[0].rgba is img


def test_volume_info_and_render_stats_print_their_fields(ctx, frame):
    vol = umbra.Volume(ctx, np.linspace(-2, 6, 4 * 3 * 2, dtype=np.float32).reshape(2, 3, 4),
                       spacing=(0.5, 1, 2))
    text = repr(vol.info)
    assert text.startswith("umbra.VolumeInfo(dims=(4, 3, 2), spacing=(0.5, 1, 2), "
                           "extent=(2, 3, 4), value_range=(-2, 6), ")
    for name in ("brick_size=", "device_bytes=", "transform_given=False",
                 "origin=(-0.75, -1, -1)",
                 "directions=((1, 0, 0), (0, 1, 0), (0, 0, 1))", "center=(0, 0, 0)",
                 "diagonal=5.38516"):
        assert name in text, (name, text)
    _, stats = frame
    text = repr(stats)
    assert text.startswith("umbra.RenderStats(shadow_build_ms=")
    for name in ("render_ms=", "shadow_rebuilt=True", "shadow_memory_bytes=",
                 f"light_channels={stats.light_channels}",
                 f"samples={stats.samples}", f"map_size={stats.map_size}"):
        assert name in text, (name, text)
