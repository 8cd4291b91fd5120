# SPDX-License-Identifier: Apache-2.0
"""Arrays as users have them: every real, integer and bool dtype makes a volume, stored in the
type the Volume docstring states (bool -> uint8; float16, float64 -> float32; other integers ->
the first of uint8, uint16, int16 that holds every value, else float32). Each is checked against
the same values handed over in that stored type: the same value range, device bytes and pixels."""

import numpy as np
import pytest

import umbra

W, H = 40, 30
N = 14


@pytest.fixture(scope="module")
def tf(ctx):
    return umbra.TransferFunction.from_points(ctx, [(0.0, 1, 1, 1, 0), (0.3, 1, 0.6, 0.3, 0.05),
                                                    (1.0, 0.4, 0.7, 1, 0.6)])


def blob(lo, hi):
    """A smooth, asymmetric volume spanning lo..hi (float64), (z, y, x) of N x N x (N + 3)."""
    z, y, x = np.mgrid[-1:1:N * 1j, -1:1:N * 1j, -1:1:(N + 3) * 1j]
    b = np.exp(-3 * ((x - 0.2) ** 2 + 2 * y ** 2 + (z + 0.1) ** 2)) + 0.3 * (x > 0.5)
    return lo + (hi - lo) * (b - b.min()) / (b.max() - b.min())


def picture(ctx, tf, data):
    with umbra.Volume(ctx, data, spacing=(1, 1, 1)) as vol, \
            umbra.Renderer(ctx, vol, tf) as r:
        return r.render(W, H, technique="reference"), vol.info


def same_volume(ctx, tf, given, stored):
    """given (a dtype umbra converts) and stored (the type it should become) make one volume."""
    assert stored.dtype in (np.uint8, np.uint16, np.int16, np.float32)
    before = given.copy()
    img, info = picture(ctx, tf, given)
    ref, ref_info = picture(ctx, tf, stored)
    assert np.array_equal(given, before)            # the caller's array is not touched
    assert info.value_range == ref_info.value_range
    assert info.device_bytes == ref_info.device_bytes
    assert np.array_equal(img, ref)
    assert np.ptp(img[..., :3]) > 0.1                 # not two blank pictures


# (dtype, lo, hi, stored): integers go to the narrowest type that keeps every value
INTEGER_CASES = [
    (np.int8, 0, 100, np.uint8),
    (np.int8, -100, 100, np.int16),
    (np.int32, 0, 255, np.uint8),
    (np.int32, 0, 4095, np.uint16),
    (np.int32, -1024, 3071, np.int16),
    (np.int32, -70000, 70000, np.float32),
    (np.uint32, 0, 65535, np.uint16),
    (np.uint32, 0, 4_000_000_000, np.float32),
    (np.int64, -32768, 32767, np.int16),
    (np.int64, 0, 3 * 2**40, np.float32),
    (np.uint64, 10, 200, np.uint8),
    (np.uint64, 0, 2**64 - 1, np.float32),
]


def integers(dtype, lo, hi):
    """blob's shape over lo..hi in dtype, lo and hi both present, computed in Python integers
    (exact for 64-bit types)."""
    frac = blob(0.0, 1.0)
    span = hi - lo
    values = [lo + min(span, int(round(f * span))) for f in frac.flat]
    return np.array(values, dtype=dtype).reshape(frac.shape)


@pytest.mark.parametrize("dtype,lo,hi,stored", INTEGER_CASES,
                         ids=[f"{np.dtype(c[0]).name}-{c[2]}-{np.dtype(c[3]).name}"
                              for c in INTEGER_CASES])
def test_integers_are_stored_in_the_narrowest_type_that_holds_them(ctx, tf, dtype, lo, hi, stored):
    given = integers(dtype, lo, hi)
    assert given.dtype == dtype and given.min() == lo and given.max() == hi
    same_volume(ctx, tf, given, given.astype(stored))


def test_bool_is_stored_as_uint8(ctx, tf):
    mask = blob(0.0, 1.0) > 0.4
    same_volume(ctx, tf, mask, mask.astype(np.uint8))


@pytest.mark.parametrize("dtype", [np.float16, np.float64])
def test_other_floats_are_stored_as_float32(ctx, tf, dtype):
    given = blob(-1.5, 700.0).astype(dtype)
    same_volume(ctx, tf, given, given.astype(np.float32))


@pytest.mark.parametrize("given", [">f8", ">i4", ">u2", "<f8", "longdouble"])
def test_other_byte_orders_and_long_double(ctx, tf, given):
    """A big-endian file's voxels (nibabel hands them over so) and long double, made native by
    NumPy first, then stored as their native twins are."""
    values = np.round(blob(0.0, 3000.0))
    native = {"f": np.float32, "i": np.uint16, "u": np.uint16}[np.dtype(given).kind]
    same_volume(ctx, tf, values.astype(given), values.astype(native))


def test_float64_beyond_float32_is_refused_by_voxel(ctx):
    data = np.ones((2, 3, 4))
    data[1, 2, 3] = -1e300
    with pytest.raises(umbra.Error, match=r"voxel 23 \(x 3, y 2, z 1\) is -1e\+300, beyond "
                                          r"float32's range") as e:
        umbra.Volume(ctx, data)
    assert e.value.status == umbra.Status.ERROR_INVALID_ARGUMENT


def test_converted_nan_is_named_by_the_c_library(ctx):
    for dtype in (np.float64, np.float16):
        data = np.ones((4, 4, 4), dtype)
        data[1, 2, 3] = np.nan
        with pytest.raises(umbra.Error, match=r"umbra_volume_create: voxel 27 is nan"):
            umbra.Volume(ctx, data)


def test_layout_is_never_guessed(ctx):
    # a converted dtype is still refused when strided: a (x, y, z) Fortran array is not (z, y, x)
    with pytest.raises(umbra.Error, match="not C-contiguous"):
        umbra.Volume(ctx, np.asfortranarray(np.zeros((4, 5, 6))))
    with pytest.raises(umbra.Error, match="not C-contiguous"):
        umbra.Volume(ctx, np.zeros((4, 5, 12), np.int32)[:, :, ::2])
    with pytest.raises(umbra.Error, match=r"need a 3-D array"):
        umbra.Volume(ctx, np.zeros((4, 5), np.int64))
    with pytest.raises(umbra.Error, match="not C-contiguous"):
        umbra.Volume(ctx, np.zeros((4, 5, 6), ">f4", order="F"))
    with pytest.raises(umbra.Error, match="dtype complex128 is not supported"):
        umbra.Volume(ctx, np.zeros((4, 5, 6), complex))
    with pytest.raises(umbra.Error, match="a ndarray is not an array"):
        umbra.Volume(ctx, np.zeros((4, 5, 6), object))


def test_empty_converted_array_is_refused_by_size(ctx):
    with pytest.raises(umbra.Error, match="dims 4 x 3 x 0"):
        umbra.Volume(ctx, np.zeros((0, 3, 4), np.float64))
    with pytest.raises(umbra.Error, match="dims 4 x 3 x 0"):
        umbra.Volume(ctx, np.zeros((0, 3, 4), np.int64))
