# SPDX-License-Identifier: Apache-2.0
"""The volume-rendering features as Python keywords (#31): RenderOptions(mode=...), Renderer.set_clip
(planes, crop), (z, y, x, c) multi-channel volumes with Renderer.set_channel_tf, label maps
(Volume(labels=True)) and Volume.update. Each against an independent expectation: a NumPy
projection, the same render of a volume with the clipped region zeroed, the single-channel render,
the label's table entry, a fresh volume of the updated voxels."""

import numpy as np
import pytest

import umbra

N = 16
W = H = 24


def z_profile():
    # Normalised values along z (constant in x and y): plateaus at 0.2 (k <= 3) and 1.0 (k 6..9)
    # and 0.5 (k >= 12), linear between, so that MIP and MinIP hit a plateau exactly.
    knots_k = [0, 3, 6, 9, 12, 15]
    knots_v = [0.2, 0.2, 1.0, 1.0, 0.5, 0.5]
    return np.interp(np.arange(N), knots_k, knots_v).astype(np.float32)


def z_volume():
    prof = z_profile()
    return np.ascontiguousarray(np.broadcast_to(prof[:, None, None], (N, N, N)))


def grey_tf(ctx):
    # entry at m: (m, m, m, 1), linear between two rows: the pixel is m itself
    return umbra.TransferFunction(ctx, np.array([[0, 0, 0, 1], [1, 1, 1, 1]], np.float32))


def top_camera():
    # looks down -z, orthographic: every ray through the middle pixels crosses the whole z range
    return umbra.Camera((0, 0, 3 * N), (0, 0, 0), up=(0, 1, 0), ortho_height=1.5 * N)


def centre(img):
    return img[H // 2 - 2:H // 2 + 2, W // 2 - 2:W // 2 + 2, :3]


@pytest.mark.parametrize("mode", ["mip", "minip", "average"])
def test_projection_modes_against_numpy(ctx, mode):
    vol = umbra.Volume(ctx, z_volume(), value_range=(0.0, 1.0))
    prof = z_profile().astype(np.float64)
    # the brute force: the trilinear (here linear in z) profile at fine steps over the box's
    # z range [-0.5, N - 0.5] (clamped at the outer samples)
    zs = np.linspace(-0.5, N - 0.5, 4001)
    along = np.interp(zs, np.arange(N), prof)
    want = {"mip": along.max(), "minip": along.min(), "average": along.mean()}[mode]
    with umbra.Renderer(ctx, vol, grey_tf(ctx), camera=top_camera()) as r:
        r.set_options(mode=mode, step=0.25)
        assert r.options.mode == umbra.RenderMode[mode.upper()]
        img = r.render(W, H)
    got = centre(img)
    tol = 1e-5 if mode != "average" else 0.01     # the mean of the samples, not the integral
    assert np.allclose(got, want, atol=tol), (mode, got.min(), got.max(), want)


def test_projection_mode_refused_by_name(ctx):
    vol = umbra.Volume(ctx, z_volume(), value_range=(0.0, 1.0))
    with umbra.Renderer(ctx, vol, grey_tf(ctx), camera=top_camera()) as r:
        with pytest.raises(TypeError, match="mode='brightest'"):
            r.set_options(mode="brightest")
        r.set_options(mode="mip")
        with pytest.raises(umbra.Error, match="(?i)mip"):
            r.render(W, H, technique="threshold")
        r.set_shadow(technique="none")
        assert r.render(W, H).shape == (H, W, 4)    # still usable


def occluder_scene():
    # a slab (y 10..12) above a floor slab (y 2..4); lit from +y
    data = np.zeros((N, N, N), np.float32)
    data[:, 10:13, :] = 1.0
    data[:, 2:5, :] = 1.0
    return data


def slab_tf(ctx):
    return umbra.TransferFunction(ctx, np.array([[1, 1, 1, 0], [1, 0.8, 0.6, 0.6]], np.float32))


CROP = ((-0.5, -0.5, -0.5), (N - 0.5, 7.5, N - 0.5))    # keeps y < 7.5: the upper slab goes


def test_clip_view_equals_the_zeroed_volume(ctx):
    data = occluder_scene()
    zeroed = data.copy()
    zeroed[:, 8:, :] = 0.0
    side = umbra.Camera((2.2 * N, 0.6 * N, 1.7 * N), (0, 0, 0))
    light = umbra.Light.directional((0.1, -1, 0.2))
    with umbra.Renderer(ctx, umbra.Volume(ctx, data), slab_tf(ctx), camera=side,
                        light=light) as r, \
            umbra.Renderer(ctx, umbra.Volume(ctx, zeroed), slab_tf(ctx), camera=side,
                           light=light) as z:
        full = r.render(W, H)
        r.set_clip(crop=CROP)
        assert r.crop == CROP and r.clip_planes == []
        clipped = r.render(W, H)
        want = z.render(W, H)
        assert np.abs(clipped - want).max() < 1e-5
        assert np.abs(full - want).max() > 0.05     # the crop changed the image
        # a plane keeping y <= 0 (world; index y < 7.5) does the same
        r.set_clip(planes=[(0, -1, 0, 0)])
        assert r.crop is None and r.clip_planes == [(0.0, -1.0, 0.0, 0.0)]
        assert np.abs(r.render(W, H) - want).max() < 1e-5
        r.set_clip()
        assert np.array_equal(r.render(W, H), full)


@pytest.mark.parametrize("technique", ["reference", "threshold", "deep", "cssm"])
def test_clipped_occluder_casts_no_shadow(ctx, technique):
    vol = umbra.Volume(ctx, occluder_scene())
    below = np.array([[0, -1.0, 0]], np.float32)   # world y -1: index y 6.5, between the slabs
    with umbra.Renderer(ctx, vol, slab_tf(ctx), light=umbra.Light.directional((0, -1, 0))) as r:
        r.set_shadow(technique=technique)
        lit = r.query_shadow(below)
        assert lit.max() < 0.5, lit                 # the upper slab shadows the gap
        r.set_clip(crop=CROP)
        assert np.allclose(r.query_shadow(below), 1.0, atol=0.02)


def test_bad_clip_refused_by_name(ctx):
    with umbra.Renderer(ctx) as r:
        with pytest.raises(umbra.Error, match="7 planes, at most 6"):
            r.set_clip(planes=[(0, 1, 0, 0)] * 7)
        with pytest.raises(umbra.Error, match="(?i)plane 1"):
            r.set_clip(planes=[(0, 1, 0, 0), (0, 0, 0, 1)])
        with pytest.raises(umbra.Error, match="(?i)nan"):
            r.set_clip(planes=[(float("nan"), 1, 0, 0)])
        with pytest.raises(umbra.Error, match="(?i)crop"):
            r.set_clip(crop=((5, 0, 0), (1, 1, 1)))
        assert r.clip_planes == [] and r.crop is None   # nothing changed


def test_multi_channel_volume(ctx):
    rng = np.random.default_rng(3)
    c0 = rng.random((N, N, N), dtype=np.float32)
    data = np.stack([c0, np.zeros_like(c0)], axis=-1)   # (z, y, x, 2), channel 1 empty
    vol = umbra.Volume(ctx, data, value_range=(0.0, 1.0))
    info = vol.info
    assert info.channels == 2 and vol.shape == (N, N, N)
    assert info.channel_ranges == ((0.0, 1.0), (0.0, 1.0))
    tf0 = umbra.TransferFunction(ctx, np.array([[1, 0.5, 0.2, 0], [1, 0.5, 0.2, 0.3]], np.float32))
    tf1 = umbra.TransferFunction(ctx, np.array([[0, 1, 0, 0], [0, 1, 0, 0.5]], np.float32))
    light = umbra.Light.directional((0.3, -1, 0.1))
    # the threshold map (the reference takes the midpoint rule for a mixture, so differs from
    # the single channel's by its step error, tests/test_channels.c)
    with umbra.Renderer(ctx, vol, tf0, light=light) as r:
        r.set_shadow(technique="threshold")
        with pytest.raises(umbra.Error, match="channel 1"):
            r.render(W, H)                            # channel 1 has no transfer function yet
        r.set_channel_tf(1, tf1)
        got = r.render(W, H)
    # channel 1 is empty (alpha 0 at 0): the mixture is channel 0 alone
    with umbra.Renderer(ctx, umbra.Volume(ctx, c0, value_range=(0.0, 1.0)), tf0,
                        light=light) as s:
        s.set_shadow(technique="threshold")
        want = s.render(W, H)
    assert np.abs(got - want).max() < 1e-5
    assert want[..., 3].max() > 0.3
    with pytest.raises(umbra.Error, match="5 channels"):
        umbra.Volume(ctx, np.zeros((4, 4, 4, 5), np.float32))
    with umbra.Renderer(ctx, vol, tf0) as r, pytest.raises(umbra.Error, match="channel"):
        r.set_channel_tf(4, tf1)


def test_label_map_colours(ctx):
    labels = np.zeros((N, N, N), np.uint8)
    labels[:, :, : N // 2] = 3
    labels[:, :, N // 2:] = 5
    vol = umbra.Volume(ctx, labels, labels=True)
    assert vol.info.labels
    table = np.zeros((8, 4), np.float32)
    table[3] = (1, 0, 0, 1)                          # label 3: opaque red
    table[5] = (0, 0, 1, 1)                          # label 5: opaque blue
    with umbra.Renderer(ctx, vol, umbra.TransferFunction(ctx, table), camera=top_camera(),
                        options=umbra.RenderOptions(ambient=(0, 0, 0))) as r:
        img = r.render(W, H)
        # nearest sampling: exact colours on either side of the boundary, no purple blend
        left, right = img[H // 2, W // 2 - 3, :3], img[H // 2, W // 2 + 2, :3]
        assert np.allclose(left, (1, 0, 0), atol=1e-6), left
        assert np.allclose(right, (0, 0, 1), atol=1e-6), right
        r.set_options(mode="mip")
        with pytest.raises(umbra.Error, match="(?i)label"):
            r.render(W, H)
    with pytest.raises(umbra.Error, match="(?i)label"):
        umbra.Volume(ctx, np.zeros((4, 4, 4), np.float32), labels=True)


def test_volume_update_equals_a_fresh_volume(ctx):
    rng = np.random.default_rng(4)
    a = (rng.random((N, N, N)) * 200).astype(np.uint8)
    b = a.copy()
    b[4:9, 2:7, 5:12] = (rng.random((5, 5, 7)) * 255).astype(np.uint8)
    tf = slab_tf(ctx)
    light = umbra.Light.directional((0.2, -1, 0.3))
    vol = umbra.Volume(ctx, a, value_range=(0, 255))
    with umbra.Renderer(ctx, vol, tf, light=light) as r, \
            umbra.Renderer(ctx, umbra.Volume(ctx, b, value_range=(0, 255)), tf, light=light) as f:
        r.set_shadow(technique="threshold")
        f.set_shadow(technique="threshold")
        before = r.render(W, H)
        vol.update(np.ascontiguousarray(b[4:9, 2:7, 5:12]), origin=(5, 2, 4))   # x, y, z
        assert vol.info.version == 1
        got = r.render(W, H)
        assert r.stats.shadow_rebuilt
        assert np.array_equal(got, f.render(W, H))
        assert not np.array_equal(got, before)
        # a whole new time step
        vol.update(a)
        assert vol.info.version == 2
        assert np.array_equal(r.render(W, H), before)
    with pytest.raises(umbra.Error, match="not the volume's uint8"):
        vol.update(a.astype(np.float32))
    with pytest.raises(umbra.Error, match=r"\(z, y, x\)"):
        vol.update(np.zeros((4, 4), np.uint8))
    with pytest.raises(umbra.Error, match="lie inside the volume"):
        vol.update(np.zeros((4, 4, 4), np.uint8), origin=(14, 0, 0))
    assert vol.info.version == 2                      # the refused updates changed nothing
