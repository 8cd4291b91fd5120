# SPDX-License-Identifier: Apache-2.0
"""The examples run: a NIfTI file written with nibabel rendered with shadows, and the notebook
helpers returning arrays and PNGs."""

import importlib.util
import pathlib

import numpy as np
import pytest

import umbra

EXAMPLES = pathlib.Path(__file__).resolve().parents[1] / "examples"


def load(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_nifti_with_shadows(ctx, tmp_path):
    nib = pytest.importorskip("nibabel")
    if not umbra.has_image_io:
        pytest.importorskip("PIL", reason="without umbra's image I/O the example writes through "
                            "Pillow")
    ex = load("render_nifti")
    nii = tmp_path / "demo.nii.gz"
    ex.make_demo(str(nii), n=32)
    # from_nibabel places it where umbra's own NIfTI loader places it
    with umbra.Volume.from_nibabel(ctx, nib.load(nii)) as mine, \
            ctx.load_volume(str(nii)) as theirs:
        assert mine.shape == (32, 32, 32)
        for k in ("spacing", "origin", "directions", "center", "value_range"):
            assert getattr(mine.info, k) == getattr(theirs.info, k), k
        assert mine.info.spacing == pytest.approx((0.9, 0.9, 1.2))
        assert mine.info.origin == pytest.approx((28.8, 28.8, -38.4))
        assert np.array_equal(mine.info.directions, np.diag([-1.0, -1, 1]))
    png = tmp_path / "demo.png"
    shadowed = ex.render(str(nii), str(png), "cssm", (64, 48), map_size=256)
    # with a ParaView preset in Hounsfield units
    preset = EXAMPLES.parents[1] / "examples" / "presets" / "ct_bone.json"
    bone = ex.render(str(nii), str(tmp_path / "bone.png"), "cssm", (64, 48), tf_path=str(preset))
    assert np.ptp(bone[..., :3]) > 0.2
    plain = ex.render(str(nii), str(tmp_path / "plain.png"), "none", (64, 48))
    if umbra.has_image_io:
        assert ctx.read_image(str(png)).shape == (48, 64, 4)
    else:   # written through Pillow: the render's own pixels
        from PIL import Image
        assert np.array_equal(np.asarray(Image.open(png)), umbra.to_srgb8(shadowed))
    # the shadow falls on the ground plane: the shadowed picture is darker
    assert shadowed[..., :3].mean() < plain[..., :3].mean() - 0.01


def test_notebook_helpers(ctx, tmp_path):
    pytest.importorskip("PIL")
    nb = load("notebook")
    img = nb.render_scene("slab", technique="deep", width=40, height=30, ctx=ctx, map_size=128)
    assert img.shape == (30, 40, 4) and img.dtype == np.float32
    u8 = nb.to_srgb8(img)
    assert u8.shape == (30, 40, 4) and u8.dtype == np.uint8
    pic = nb.show(img)
    assert pic.size == (40, 30)
    pic.save(tmp_path / "slab.png")
    assert (tmp_path / "slab.png").stat().st_size > 0
