# SPDX-License-Identifier: Apache-2.0
"""Issue 13's acceptance through Python: a NIfTI volume written with nibabel (and a MetaImage
written here) and a ParaView preset rendered with technique cssm from Python and by umbra-render
--volume x.nii.gz --tf preset.json (x.mha) give the same pixels. Also: transfer-function data
ranges and ParaView presets from Python."""

import json
import os
import subprocess

import numpy as np
import pytest

import umbra

from conftest import REPO

# umbra-render's defaults for a --volume (examples/umbra_render.c): camera direction, field of
# view, light, ground plane and background.
CLI_CAMERA_DIR = (0.75, 0.5, 1.0)
CLI_LIGHT_DIR = (0.45, -1.0, 0.25)
CLI_BACKGROUND = (0.08, 0.08, 0.1, 1.0)
W, H = 80, 64
CT_BONE = REPO / "examples" / "presets" / "ct_bone.json"


def write_ct(path):
    """A small int16 'CT' in Hounsfield units (a bone shell around soft tissue, a denser blob off
    centre) with an affine that flips x and y, rotates about two axes, has anisotropic voxels and
    an origin away from 0."""
    nib = pytest.importorskip("nibabel")
    n = 24
    z, y, x = np.mgrid[-1:1:n * 1j, -1:1:n * 1j, -1:1:(n + 4) * 1j]
    r = np.sqrt(x * x + (1.2 * y) ** 2 + z * z)
    hu = np.where(r < 0.85, 40.0, -1000.0) + np.where((r > 0.65) & (r < 0.85), 900.0, 0.0)
    hu += 300 * np.exp(-((x - 0.2) ** 2 + y ** 2 + z ** 2) / 0.02)
    c, s, c2, s2 = np.cos(0.4), np.sin(0.4), np.cos(0.3), np.sin(0.3)
    rot = np.array([[c2, -s2, 0], [s2, c2, 0], [0, 0, 1]]) @ np.array([[c, 0, s], [0, 1, 0],
                                                                     [-s, 0, c]])
    A = np.eye(4)
    A[:3, :3] = rot @ np.diag([-0.9, -0.8, 1.3])     # not symmetric: a transposition shows
    A[:3, 3] = (40.0, 25.0, -60.0)
    nib.save(nib.Nifti1Image(np.asfortranarray(hu.astype(np.int16).T), A), path)


def volume_from_nifti(ctx, path):
    """The README's mapping by hand (Volume.from_nibabel does it too, test_adapters.py): nibabel's
    (x, y, z) array and affine to umbra.Volume."""
    nib = pytest.importorskip("nibabel")
    img = nib.load(path)
    A = img.affine
    # |column a|, a = index axis x, y, z; rounded to float32 before the division, as umbra's
    # NIfTI loader does, so that the directions come out bit for bit the same as the CLI's
    spacing = np.linalg.norm(A[:3, :3], axis=0).astype(np.float32)
    zyx = np.ascontiguousarray(np.asanyarray(img.dataobj).T)
    return umbra.Volume(ctx, zyx, spacing=tuple(spacing), origin=tuple(A[:3, 3]),
                        directions=(A[:3, :3] / spacing).T)


def test_nifti_and_paraview_preset_match_the_cli(ctx, cli, read_exr, tmp_path):
    nii = tmp_path / "x.nii.gz"
    write_ct(nii)
    exr = tmp_path / "x.exr"
    env = dict(os.environ)
    env.setdefault("POCL_CACHE_DIR", str(tmp_path / "pocl-cache"))
    subprocess.run([str(cli), "--volume", str(nii), "--tf", str(CT_BONE), "--technique", "cssm",
                    "--size", f"{W}x{H}", "--out", str(exr)],
                   check=True, env=env, capture_output=True)
    c_pixels = read_exr(exr)

    with volume_from_nifti(ctx, nii) as vol, ctx.load_transfer_function(str(CT_BONE)) as tf:
        assert tf.range == (-1024.0, 3071.0)             # the preset's x range, in HU
        info = vol.info
        assert info.transform_given and info.value_range[0] == -1000.0
        camera = umbra.Camera.orbit(CLI_CAMERA_DIR, info.diagonal, 30, center=info.center)
        with umbra.Renderer(ctx, vol, tf, camera=camera,
                            light=umbra.Light.directional(CLI_LIGHT_DIR)) as r:
            r.set_options(ground_plane=True, background=CLI_BACKGROUND)
            py_pixels = r.render(W, H, technique="cssm")
    assert py_pixels.shape == c_pixels.shape == (H, W, 4)
    # the same bound as test_render's comparison with the CLI on the built-in scene
    assert np.max(np.abs(py_pixels - c_pixels)) <= 1e-6
    # a picture, not two blank ones: the volume covers a good part of the image
    assert np.ptp(py_pixels[..., :3]) > 0.2
    assert np.mean(np.abs(py_pixels - np.array(CLI_BACKGROUND, np.float32)) > 0.02) > 0.1


def test_tf_range_keyword_and_property(ctx):
    table = np.array([[0, 0, 0, 0], [1, 1, 1, 1]], np.float32)
    with umbra.TransferFunction(ctx, table) as tf:
        assert tf.range is None
        tf.range = (-1000, 3000)
        assert tf.range == (-1000.0, 3000.0)
        with pytest.raises(umbra.Error, match="umbra_transfer_function_set_range") as e:
            tf.range = (5, 5)
        assert e.value.status == umbra.Status.ERROR_INVALID_ARGUMENT
        assert tf.range == (-1000.0, 3000.0)
    with umbra.TransferFunction(ctx, table, range=(0, 4095)) as tf:
        assert tf.range == (0.0, 4095.0)
    # from_points with a range: point values are data values, like the text format's 'range'
    tf = umbra.TransferFunction.from_points(ctx, [(-1000, 0, 0, 0, 0), (0, 1, 1, 1, 0.5),
                                                  (1000, 1, 1, 1, 1)], resolution=5,
                                            range=(-1000, 1000))
    assert tf.range == (-1000.0, 1000.0)
    assert np.allclose(tf.table[:, 3], [0, 0.25, 0.5, 0.75, 1])
    with pytest.raises(umbra.Error, match=r"point 1 value 2000.* outside the range"):
        umbra.TransferFunction.from_points(ctx, [(0, 0, 0, 0, 0), (2000, 1, 1, 1, 1)],
                                           range=(0, 1000))
    with pytest.raises(umbra.Error, match="must be finite with lo < hi"):
        umbra.TransferFunction.from_points(ctx, [(0, 0, 0, 0, 0)], range=(1, 0))


def test_tf_range_places_the_table_in_data_units(ctx):
    # A volume in HU: 200 HU is opaque white under a TF given in HU, whatever the volume's range.
    data = np.full((8, 8, 8), -1000, np.int16)
    data[2:6, 2:6, 2:6] = 200
    pts = [(-1000, 0, 0, 0, 0), (100, 0, 0, 0, 0), (150, 1, 1, 1, 1), (3000, 1, 1, 1, 1)]
    images = []
    for value_range in [None, (-2000, 4000)]:
        with umbra.Volume(ctx, data, value_range=value_range) as vol:
            tf = umbra.TransferFunction.from_points(ctx, pts, 1024, range=(-1000, 3000))
            with umbra.Renderer(ctx, vol, tf) as r:
                r.set_options(shading=False, background=(0, 0, 0, 1))
                images.append(r.render(32, 32))
    assert np.allclose(images[0], images[1], atol=2e-3)
    assert images[0][16, 16, 0] > 0.5


def test_paraview_presets(ctx, tmp_path):
    tf = ctx.load_paraview(str(CT_BONE), resolution=64)
    assert len(tf) == 64 and tf.range == (-1024.0, 3071.0)
    tf2 = umbra.TransferFunction.load_paraview(ctx, str(CT_BONE), preset="CT Bone (HU)",
                                               resolution=64, range=(-500, 500))
    assert tf2.range == (-500.0, 500.0)
    # .json through load_transfer_function: load_paraview's defaults
    tf3 = ctx.load_transfer_function(str(CT_BONE))
    assert np.array_equal(tf3.table, ctx.load_paraview(str(CT_BONE)).table)
    with pytest.raises(umbra.Error, match="No Such Preset") as e:
        ctx.load_paraview(str(CT_BONE), preset="No Such Preset")
    # a preset written here: two points, RGB and opacity
    preset = [{"Name": "two", "ColorSpace": "RGB", "RGBPoints": [0, 0, 0, 0, 10, 1, 0, 0],
               "Points": [0, 0, 0.5, 0, 10, 1, 0.5, 0]}]
    path = tmp_path / "two.json"
    path.write_text(json.dumps(preset))
    tf4 = ctx.load_paraview(str(path), resolution=3)
    assert tf4.range == (0.0, 10.0)
    assert np.allclose(tf4.table, [[0, 0, 0, 0], [0.5, 0, 0, 0.5], [1, 0, 0, 1]], atol=1e-6)
    # malformed files raise ERROR_FORMAT naming what is wrong
    for text, what in [("[{", "JSON"), ('[{"Name": "x"}]', "RGBPoints"),
                       ('[{"RGBPoints": [5, 0, 0, 0, 1, 1, 1, 1]}]', "must ascend")]:
        path.write_text(text)
        with pytest.raises(umbra.Error) as e:
            ctx.load_paraview(str(path))
        assert e.value.status == umbra.Status.ERROR_FORMAT, e.value
        assert what.lower() in e.value.message.lower(), e.value.message
    with pytest.raises(umbra.Error) as e:
        ctx.load_paraview(str(CT_BONE), resolution=1)
    assert e.value.status == umbra.Status.ERROR_INVALID_ARGUMENT


def write_mha(path, zyx, spacing, offset, matrix, compressed):
    """A MetaImage as ITK writes it: a text header, then the voxels (x fastest), zlib-compressed
    when asked."""
    import zlib
    types = {np.dtype(np.uint8): "MET_UCHAR", np.dtype(np.int16): "MET_SHORT",
             np.dtype(np.float32): "MET_FLOAT"}
    data = np.ascontiguousarray(zyx).astype(zyx.dtype.newbyteorder("<")).tobytes()
    if compressed:
        data = zlib.compress(data)
    nz, ny, nx = zyx.shape
    head = ["ObjectType = Image", "NDims = 3", "BinaryData = True",
            "BinaryDataByteOrderMSB = False", f"CompressedData = {compressed}"]
    if compressed:
        head.append(f"CompressedDataSize = {len(data)}")
    head += ["TransformMatrix = " + " ".join(repr(float(v)) for v in np.ravel(matrix)),
             "Offset = " + " ".join(repr(float(v)) for v in offset),
             "CenterOfRotation = 0 0 0",
             "ElementSpacing = " + " ".join(repr(float(v)) for v in spacing),
             f"DimSize = {nx} {ny} {nz}", "AnatomicalOrientation = RAI",
             f"ElementType = {types[zyx.dtype]}", "ElementDataFile = LOCAL"]
    path.write_bytes(("\n".join(head) + "\n").encode() + data)


@pytest.mark.parametrize("dtype,compressed", [(np.int16, True), (np.uint8, False),
                                              (np.float32, True)])
def test_metaimage_loads_as_the_array_and_matches_the_cli(ctx, cli, read_exr, tmp_path, dtype,
                                                          compressed):
    """An .mha written here loads with the header's spacing, offset and axis directions and the
    array's values, and umbra-render --volume x.mha --tf preset draws what Python draws from the
    loaded volume."""
    n = 20
    z, y, x = np.mgrid[-1:1:n * 1j, -1:1:n * 1j, -1:1:(n + 4) * 1j]
    r = np.sqrt(x * x + (1.3 * y) ** 2 + z * z)
    zyx = (np.where(r < 0.8, 200.0, 10.0) + 40 * x).astype(dtype)
    spacing = (0.9, 1.1, 1.7)
    offset = (-12.0, 30.5, 4.25)
    c, s = np.cos(0.5), np.sin(0.5)
    matrix = np.array([[c, s, 0], [-s, c, 0], [0, 0, -1]])     # row a: index axis a's direction
    mha = tmp_path / "x.mha"
    write_mha(mha, zyx, spacing, offset, matrix, compressed)
    exr = tmp_path / "x.exr"
    env = dict(os.environ)
    env.setdefault("POCL_CACHE_DIR", str(tmp_path / "pocl-cache"))
    preset = REPO / "examples" / "presets" / "cool_to_warm.json"
    subprocess.run([str(cli), "--volume", str(mha), "--tf", str(preset), "--technique", "cssm",
                    "--size", f"{W}x{H}", "--out", str(exr)], check=True, env=env,
                   capture_output=True)
    c_pixels = read_exr(exr)
    with ctx.load_volume(str(mha)) as theirs, \
            umbra.Volume(ctx, zyx, spacing=spacing, origin=offset, directions=matrix) as mine:
        a, b = mine.info, theirs.info
        assert b.transform_given
        assert a.dims == b.dims == (n + 4, n, n)
        assert np.allclose(a.spacing, b.spacing, rtol=1e-6)
        assert np.allclose(b.origin, offset, atol=1e-6)
        assert np.allclose(a.directions, b.directions, atol=1e-6)
        assert np.allclose(a.center, b.center, atol=1e-4)
        assert a.value_range == b.value_range
    with ctx.load_volume(str(mha)) as vol, ctx.load_transfer_function(str(preset)) as tf:
        info = vol.info
        camera = umbra.Camera.orbit(CLI_CAMERA_DIR, info.diagonal, 30, center=info.center)
        with umbra.Renderer(ctx, vol, tf, camera=camera,
                            light=umbra.Light.directional(CLI_LIGHT_DIR)) as rnd:
            rnd.set_options(ground_plane=True, background=CLI_BACKGROUND)
            py_pixels = rnd.render(W, H, technique="cssm")
    assert py_pixels.shape == c_pixels.shape == (H, W, 4)
    assert np.max(np.abs(py_pixels - c_pixels)) <= 1e-6
    assert np.ptp(py_pixels[..., :3]) > 0.2
