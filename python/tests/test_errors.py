# SPDX-License-Identifier: Apache-2.0
"""Bad input raises umbra.Error with umbra's status and a message that names the value, and leaves
the context usable."""

import numpy as np
import pytest

import umbra

INVALID = umbra.Status.ERROR_INVALID_ARGUMENT


def raises_invalid(match):
    return pytest.raises(umbra.Error, match=match)


@pytest.mark.parametrize("dtype", [np.complex64, np.complex128])
def test_volume_wrong_dtype(ctx, dtype):
    with raises_invalid(np.dtype(dtype).name + " is not supported") as e:
        umbra.Volume(ctx, np.zeros((4, 4, 4), dtype))
    assert e.value.status == INVALID
    assert "a real, integer or bool array" in e.value.message


def test_volume_not_contiguous(ctx):
    data = np.zeros((8, 8, 8), np.float32)
    with raises_invalid("not C-contiguous"):
        umbra.Volume(ctx, data[:, :, ::2])
    with raises_invalid("not C-contiguous"):
        umbra.Volume(ctx, np.asfortranarray(data))


@pytest.mark.parametrize("shape", [(8, 8), (2, 2, 2, 2, 2), (64,)])
def test_volume_wrong_shape(ctx, shape):
    with raises_invalid(r"shape \(.*need a 3-D array of shape \(z, y, x\)"):
        umbra.Volume(ctx, np.zeros(shape, np.float32))


def test_volume_not_an_array(ctx):
    with raises_invalid("list is not an array"):
        umbra.Volume(ctx, [[[1.0]]])


def test_volume_nan_and_bad_spacing_from_the_c_library(ctx):
    data = np.ones((4, 4, 4), np.float32)
    data[1, 2, 3] = np.nan
    with raises_invalid(r"umbra_volume_create: voxel 27 is nan") as e:
        umbra.Volume(ctx, data)
    assert e.value.status == INVALID
    # with a given value range too (the C library scans float voxels either way), naming the
    # voxel data[1, 2, 3] by its x, y, z
    with raises_invalid(r"voxel 27 is nan \(x 3, y 2, z 1\)"):
        umbra.Volume(ctx, data, value_range=(0, 1))
    data[1, 2, 3] = -np.inf
    with raises_invalid(r"voxel 27 is -inf \(x 3, y 2, z 1\)"):
        umbra.Volume(ctx, data, value_range=(0, 1))
    with raises_invalid("spacing"):
        umbra.Volume(ctx, np.ones((4, 4, 4), np.float32), spacing=(1, 0, 1))


def test_transfer_function_bad_tables(ctx):
    with raises_invalid(r"shape \(3, 3\) is not \(N, 4\)"):
        umbra.TransferFunction(ctx, np.zeros((3, 3), np.float32))
    with raises_invalid("float64 is not float32"):
        umbra.TransferFunction(ctx, np.zeros((3, 4)))
    with raises_invalid("not C-contiguous"):
        umbra.TransferFunction(ctx, np.zeros((4, 3), np.float32).T)
    bad = np.zeros((3, 4), np.float32)
    bad[1, 2] = np.nan
    with raises_invalid("umbra_transfer_function_create"):
        umbra.TransferFunction(ctx, bad)
    with raises_invalid("umbra_transfer_function_create"):
        umbra.TransferFunction(ctx, np.full((3, 4), 2, np.float32))
    with pytest.raises(TypeError):
        umbra.TransferFunction.from_points(ctx, [(0, 1, 1, 1)])   # 4 numbers, not 5


def test_query_shadow_bad_points(ctx):
    vol = umbra.Volume(ctx, np.arange(64, dtype=np.float32).reshape(4, 4, 4))
    tf = umbra.TransferFunction(ctx, np.array([[1, 1, 1, 0], [1, 1, 1, 0.5]], np.float32))
    with umbra.Renderer(ctx, vol, tf) as r:
        r.set_shadow(technique="reference")
        with raises_invalid(r"shape \(4, 2\) is not \(N, 3\)"):
            r.query_shadow(np.zeros((4, 2), np.float32))
        with raises_invalid("float64 is not float32"):
            r.query_shadow(np.zeros((4, 3)))
        with raises_invalid("not C-contiguous"):
            r.query_shadow(np.zeros((3, 4), np.float32).T[:, :3].T.T)
        with raises_invalid(r"point 1 has a non-finite coordinate"):
            r.query_shadow(np.array([[0, 0, 0], [0, np.nan, 0]], np.float32))
        with raises_invalid("1..2\\^28 points"):
            r.query_shadow(np.zeros((0, 3), np.float32))
        # the context still works after all that
        assert r.query_shadow(np.zeros((1, 3), np.float32)).shape == (1, 3)


def test_bad_options_name_the_value(ctx):
    s = umbra.Scene(ctx, "slab", 16)
    with s.renderer() as r:
        with raises_invalid(r"map_size 8 must be 0 \(auto\) or lie in \[16, 8192\]"):
            r.set_shadow(technique="deep", map_size=8)
        with raises_invalid(r"map_texels_per_voxel 9 must be 0 .* or lie in \[0.25, 8\]"):
            r.set_shadow(technique="cssm", map_texels_per_voxel=9)
        with raises_invalid(r"cssm ray_block 4 must be 0 \(the map's own\) or lie in \[1, 3\]"):
            r.set_shadow(technique="cssm", ray_block=4)
        with pytest.raises(TypeError, match="unknown parameter 'mapsize'.*map_size"):
            r.render(8, 8, technique="deep", mapsize=64)
        with pytest.raises(TypeError, match=r"taps=-1 is not a valid int"):
            r.set_shadow(technique="cssm", taps=-1)
        with pytest.raises(TypeError, match=r"technique='shiny' is not a valid Technique"):
            r.set_shadow(technique="shiny")
        with raises_invalid("step"):
            r.set_options(step=float("nan"))
        with raises_invalid("size 0 x 8"):
            r.render(0, 8)
        assert r.render(8, 8).shape == (8, 8, 4)


def test_scene_and_context_errors(ctx):
    with raises_invalid("nowhere") as e:
        umbra.Scene(ctx, "nowhere")
    assert e.value.status == INVALID
    with pytest.raises(umbra.Error) as e:
        umbra.Context(device="no such device anywhere")
    assert e.value.status == umbra.Status.ERROR_NO_DEVICE
    assert "no such device anywhere" in e.value.message
    with pytest.raises(umbra.Error) as e:
        ctx.load_volume("/nonexistent/x.nrrd")
    assert e.value.status == umbra.Status.ERROR_IO


def test_closed_objects_raise(ctx):
    vol = umbra.Volume(ctx, np.arange(8, dtype=np.uint8).reshape(2, 2, 2))
    vol.close()
    vol.close()  # idempotent
    assert vol.closed
    with pytest.raises(ValueError, match="umbra.Volume is closed"):
        vol.info
    with pytest.raises(ValueError, match="closed"):
        umbra.Renderer(ctx, vol)
