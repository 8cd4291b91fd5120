# SPDX-License-Identifier: Apache-2.0
"""Pictures from Python: the same pixels as the C command-line tool on the built-in scene, every
shadow technique, rendering into a caller's array, shadow queries, the axis order of volumes."""

import os
import subprocess

import numpy as np
import pytest

import umbra

# umbra-render's background when --background is not given (examples/umbra_render.c).
CLI_BACKGROUND = (0.08, 0.08, 0.1, 1.0)
W, H = 96, 72


@pytest.fixture(scope="module")
def spheres(ctx):
    return umbra.Scene(ctx, "spheres")


def convolution_light(camera):
    """Convolution shadows carry only light from the viewer's side: light along the view."""
    eye, target = np.array(camera.eye), np.array(camera.target)
    return umbra.Light.directional(tuple(target - eye))


@pytest.mark.parametrize("technique", ["none", "reference", "cssm", "deep"])
def test_matches_the_cli_pixels(ctx, spheres, cli, read_exr, tmp_path, technique):
    exr = tmp_path / f"{technique}.exr"
    env = dict(os.environ)
    env.setdefault("POCL_CACHE_DIR", str(tmp_path / "pocl-cache"))
    subprocess.run([str(cli), "--scene", "spheres", "--technique", technique, "--map-size", "256",
                    "--size", f"{W}x{H}", "--out", str(exr)],
                   check=True, env=env, capture_output=True)
    c_pixels = read_exr(exr)
    with spheres.renderer() as r:
        # the scene's renderer carries the scene's options, as umbra-render's --scene does
        assert r.options == spheres.options and r.options.ground_plane
        assert r.camera == spheres.camera and r.light == spheres.light
        r.set_options(r.options, background=CLI_BACKGROUND)
        py_pixels = r.render(W, H, technique=technique, map_size=256)
    assert py_pixels.shape == c_pixels.shape == (H, W, 4)
    # The same library on the same device: the same floats, through the EXR's float32.
    assert np.max(np.abs(py_pixels - c_pixels)) <= 1e-6
    # and not a trivially equal pair of blank pictures
    assert np.ptp(py_pixels[..., :3]) > 0.2


def test_every_technique_renders_and_shadows(ctx, spheres):
    images = {}
    with spheres.renderer() as r:
        for name in umbra.technique_names():
            if name == "convolution":
                r.light = convolution_light(spheres.camera)
                # each technique against its own light: none and reference again under this light
                ref_conv = r.render(W, H, technique="reference", map_size=256)
                none_conv = r.render(W, H, technique="none")
                img = r.render(W, H, technique=name)
            else:
                r.light = spheres.light
                img = r.render(W, H, technique=name, map_size=256)
            assert img.shape == (H, W, 4) and img.dtype == np.float32
            assert np.isfinite(img).all()
            assert img[..., 3].min() >= 0 and img[..., 3].max() <= 1 + 1e-6
            assert r.stats.render_ms > 0
            images[name] = img
    def rmse(a, b):
        return float(np.sqrt(np.mean((a - b) ** 2)))

    lum = {k: float(v[..., :3].mean()) for k, v in images.items()}
    # Shadows darken the picture, and each technique lands near the exact reference: bounds
    # about 1.3x the RMSE measured here at 96x72 with 256^2 maps (none: 0.106, threshold 0.074,
    # deep 0.0046, cssm 0.019; under the viewer-side light none 0.022, convolution 0.0073).
    bounds = {"threshold": 0.095, "deep": 0.006, "cssm": 0.025}
    assert rmse(images["none"], images["reference"]) > 0.09
    for name in ("reference", "threshold", "deep", "cssm"):
        assert lum[name] < lum["none"] - 0.005, (name, lum)
    for name, bound in bounds.items():
        assert rmse(images[name], images["reference"]) < bound, (name, rmse(images[name], images["reference"]))
    assert float(ref_conv[..., :3].mean()) < float(none_conv[..., :3].mean())
    assert rmse(none_conv, ref_conv) > 0.015
    assert rmse(images["convolution"], ref_conv) < 0.01


def test_technique_parameters_reach_the_renderer(ctx, spheres):
    with spheres.renderer() as r:
        r.set_shadow(technique="cssm", map_size=128, taps=7, seed=3, ray_block=1)
        assert r.shadow.technique == umbra.Technique.CSSM
        assert (r.shadow.map_size, r.shadow.taps, r.shadow.seed) == (128, 7, 3)
        assert r.shadow.ray_block == 1
        r.render(32, 24)
        small = r.stats.shadow_memory_bytes
        r.set_shadow(technique=umbra.Technique.CSSM, map_size=256)
        r.render(32, 24)
        assert r.stats.shadow_memory_bytes == 4 * small
        assert r.stats.map_size == 256
        # parameters not given take the C defaults again, not the previous values
        assert r.shadow.taps == umbra.ShadowOptions().taps
        assert r.shadow.ray_block == 0


def test_map_size_auto_is_the_default_and_reported(ctx, spheres):
    assert umbra.ShadowOptions().map_size == umbra.MAP_SIZE_AUTO == 0
    with spheres.renderer() as r:
        r.render(32, 24, technique="threshold")
        auto = r.stats.map_size
        # the rule of include/umbra/renderer.h: a multiple of 32 within [64, 2048]
        assert 64 <= auto <= 2048 and auto % 32 == 0
        assert r.stats.shadow_memory_bytes == 4 * auto * auto
        # a draft for CSSM (1 texel per voxel instead of 3) is the threshold map's size
        assert umbra.ShadowOptions().map_texels_per_voxel == 0
        r.render(32, 24, technique="cssm", map_texels_per_voxel=1)
        assert r.stats.map_size == auto
        r.render(32, 24, technique="cssm")
        assert r.stats.map_size > auto
        r.render(32, 24, technique="none")
        assert r.stats.map_size == 0


def test_interaction_auto_drafts_while_the_light_moves(ctx, spheres):
    assert umbra.RenderOptions().interaction == umbra.Interaction.OFF
    moved = umbra.Light.directional((-0.3, -1.0, -0.5))
    with spheres.renderer() as r:
        r.set_options(spheres.options, interaction="auto")
        assert r.options.interaction == umbra.Interaction.AUTO
        r.set_shadow(technique="deep")
        r.render(32, 24)
        assert not r.stats.draft  # the first frame: nothing moved before it
        full = r.stats.map_size
        r.light = moved
        r.render(32, 24)
        assert r.stats.draft and r.stats.shadow_rebuilt and r.stats.map_size < full
        refined = r.render(32, 24)  # nothing changed: the full map
        assert not r.stats.draft and r.stats.shadow_rebuilt
    with spheres.renderer() as f:
        f.light = moved
        f.set_shadow(technique="deep")
        assert np.array_equal(refined, f.render(32, 24))
    with pytest.raises(TypeError):
        umbra.RenderOptions(interaction="sometimes")


def test_render_into_callers_array(ctx, spheres):
    out = np.full((H, W, 4), -1.0, np.float32)
    with spheres.renderer() as r:
        got = r.render(W, H, out=out)
        assert got is out
        assert np.array_equal(out, r.render(W, H))
        with pytest.raises(umbra.Error, match=r"\(72, 96, 4\)"):
            r.render(W, H, out=np.zeros((H, W, 3), np.float32))
        with pytest.raises(umbra.Error, match="float32"):
            r.render(W, H, out=np.zeros((H, W, 4), np.float64))


def test_query_shadow(ctx):
    # A homogeneous slab lit from +y: points above it are unshadowed, points below get exp(-...)
    data = np.zeros((16, 16, 16), np.float32)
    data[:, 6:10, :] = 1.0                       # y in [6, 10): 4 voxels thick
    vol = umbra.Volume(ctx, data)
    tf = umbra.TransferFunction(ctx, np.array([[1, 1, 1, 0], [1, 1, 1, 0.2]], np.float32))
    with umbra.Renderer(ctx, vol, tf, light=umbra.Light.directional((0, -1, 0))) as r:
        r.set_shadow(technique="reference", reference_step=0.05)
        pts = np.array([[0, 7.5, 0], [0, -7.5, 0]], np.float32)   # above and below the slab
        s = r.query_shadow(pts)
        assert s.shape == (2, 3) and s.dtype == np.float32
        assert np.allclose(s[0], 1.0, atol=1e-4)
        # alpha 0.2 per voxel over 4 voxels: (1 - 0.2)^4, up to the trilinear edges of the slab
        assert np.allclose(s[1], 0.8 ** 4, atol=0.03), s[1]


def test_volume_axis_order_is_z_y_x(ctx):
    data = np.zeros((5, 6, 7), np.uint8)           # z, y, x
    data[4, 5, 6] = 9
    with umbra.Volume(ctx, data, spacing=(1.0, 2.0, 3.0)) as vol:
        info = vol.info
        assert info.dims == (7, 6, 5)               # x, y, z
        assert info.spacing == (1.0, 2.0, 3.0)
        assert info.extent == (7.0, 12.0, 15.0)
        assert info.value_range == (0.0, 9.0)
        assert vol.shape == data.shape


@pytest.mark.parametrize("dtype", [np.uint8, np.uint16, np.int16, np.float32])
def test_every_supported_dtype(ctx, dtype):
    data = (np.arange(4 * 5 * 6) % 50).astype(dtype).reshape(4, 5, 6)
    with umbra.Volume(ctx, data, value_range=(0, 49)) as vol:
        assert vol.info.value_range == (0.0, 49.0)


def test_fortran_array_transposed_is_used_in_place(ctx):
    # nibabel's (x, y, z) arrays are Fortran-ordered: .T is C-contiguous, no copy needed
    xyz = np.asfortranarray(np.random.default_rng(1).random((7, 6, 5), dtype=np.float32))
    with umbra.Volume(ctx, xyz.T) as vol:
        assert vol.info.dims == (7, 6, 5)


def test_transfer_function_table_and_points(ctx):
    table = np.linspace(0, 1, 32, dtype=np.float32)[:, None].repeat(4, axis=1)
    with umbra.TransferFunction(ctx, table) as tf:
        view = tf.table
        assert len(tf) == 32 and not view.flags.writeable
        assert np.array_equal(view, table)
        assert tf.is_grey
    tf2 = umbra.TransferFunction.from_points(ctx, [(0, 1, 0, 0, 0), (1, 0, 0, 1, 1)], resolution=3)
    assert np.allclose(tf2.table, [[1, 0, 0, 0], [0.5, 0, 0.5, 0.5], [0, 0, 1, 1]])
    assert not tf2.is_grey
    tf3 = umbra.TransferFunction.from_points(ctx, np.array([[0, 1, 1, 1, 0], [1, 1, 1, 1, 1]]))
    assert len(tf3) == 256


needs_image_io = pytest.mark.skipif(not umbra.has_image_io,
                                    reason="this umbra is built without OpenImageIO (the wheel)")


@needs_image_io
def test_image_round_trip(ctx, tmp_path):
    img = np.random.default_rng(2).random((5, 7, 4), dtype=np.float32)
    ctx.write_image(str(tmp_path / "a.exr"), img)
    assert np.array_equal(ctx.read_image(str(tmp_path / "a.exr")), img)


@pytest.mark.skipif(umbra.has_image_io, reason="this umbra has image I/O")
def test_without_image_io_images_are_refused_by_name(ctx, tmp_path):
    img = np.zeros((2, 3, 4), np.float32)
    for call in (lambda p: ctx.write_image(p, img), ctx.read_image):
        with pytest.raises(umbra.Error, match="a.png.*built without OpenImageIO") as e:
            call(str(tmp_path / "a.png"))
        assert e.value.status == umbra.Status.ERROR_UNSUPPORTED
    assert not (tmp_path / "a.png").exists()


@needs_image_io
def test_to_srgb8_gives_the_c_png_writers_pixels(ctx, spheres, tmp_path):
    Image = pytest.importorskip("PIL.Image")
    with spheres.renderer() as r:
        img = r.render(W, H, technique="cssm")
    # premultiplied colours, alphas from 0 to 1 and out of range, as a render can give them
    rng = np.random.default_rng(5)
    extra = rng.random((H, W, 4), dtype=np.float32) * np.float32(1.2) - np.float32(0.1)
    extra[..., :3] *= np.clip(extra[..., 3:], 0, 1)
    for rgba in (img, extra):
        ctx.write_image(str(tmp_path / "c.png"), rgba)
        theirs = np.asarray(Image.open(tmp_path / "c.png").convert("RGBA"))
        mine = umbra.to_srgb8(rgba)
        assert mine.shape == theirs.shape == (H, W, 4) and mine.dtype == np.uint8
        # the same float32 arithmetic as io/image.cpp; powf may round one value differently
        assert np.abs(mine.astype(int) - theirs).max() <= 1
        assert np.mean(mine == theirs) > 0.999
