# SPDX-License-Identifier: Apache-2.0
"""Volumes placed in the world from Python: origin and directions reach the C library (read back
through Volume.info), a NIfTI affine handed over as the README says places the volume where
umbra's own NIfTI loader does, and bad transforms raise umbra.Error naming the problem."""

import numpy as np
import pytest

import umbra


def test_default_volume_is_the_centred_box(ctx):
    with umbra.Volume(ctx, np.zeros((2, 3, 4), np.uint8), spacing=(1, 2, 3)) as v:
        i = v.info
        assert not i.transform_given
        assert i.center == (0.0, 0.0, 0.0)
        assert i.directions == ((1, 0, 0), (0, 1, 0), (0, 0, 1))
        # voxel (0, 0, 0)'s centre: (0.5 - dims/2) * spacing, dims (x, y, z) = (4, 3, 2)
        assert i.origin == (-1.5, -2.0, -1.5)
        assert i.diagonal == pytest.approx(np.sqrt(4**2 + 6**2 + 6**2))


def test_origin_and_directions_reach_the_volume(ctx):
    # index axis x along world -y, y along world +z, z along world -x (a rotation with a mirror)
    d = ((0, -2, 0), (0, 0, 0.5), (-1, 0, 0))          # any length: normalised by the library
    with umbra.Volume(ctx, np.zeros((2, 3, 4), np.float32), spacing=(1, 2, 3),
                      origin=(10, 20, 30), directions=d) as v:
        i = v.info
        assert i.transform_given
        assert i.origin == (10.0, 20.0, 30.0)
        assert i.directions == ((0, -1, 0), (0, 0, 1), (-1, 0, 0))
        # centre = origin + sum_a (dims_a - 1)/2 * spacing_a * d_a
        want = np.array([10, 20, 30]) + 1.5 * 1 * np.array([0, -1, 0]) \
            + 1.0 * 2 * np.array([0, 0, 1]) + 0.5 * 3 * np.array([-1, 0, 0])
        assert np.allclose(i.center, want)
    # a NumPy (3, 3) array works as well as nested tuples; origin alone keeps the identity
    with umbra.Volume(ctx, np.zeros((2, 2, 2), np.uint8), directions=np.eye(3)[::-1]) as v:
        assert v.info.directions == ((0, 0, 1), (0, 1, 0), (1, 0, 0))
        assert v.info.origin == (0.0, 0.0, 0.0)
    with umbra.Volume(ctx, np.zeros((2, 2, 2), np.uint8), origin=(1, 2, 3)) as v:
        assert v.info.transform_given and v.info.origin == (1.0, 2.0, 3.0)
        assert v.info.directions == ((1, 0, 0), (0, 1, 0), (0, 0, 1))


def test_bad_transforms_raise(ctx):
    data = np.zeros((2, 2, 2), np.uint8)
    with pytest.raises(umbra.Error, match="umbra_volume_create") as e:
        umbra.Volume(ctx, data, directions=((1, 0, 0), (0.5, 1, 0), (0, 0, 1)))   # sheared
    assert e.value.status == umbra.Status.ERROR_UNSUPPORTED
    with pytest.raises(umbra.Error) as e:
        umbra.Volume(ctx, data, directions=((1, 0, 0), (0, 0, 0), (0, 0, 1)))
    assert e.value.status == umbra.Status.ERROR_INVALID_ARGUMENT
    with pytest.raises(umbra.Error) as e:
        umbra.Volume(ctx, data, origin=(float("nan"), 0, 0))
    assert e.value.status == umbra.Status.ERROR_INVALID_ARGUMENT
    with pytest.raises(TypeError):
        umbra.Volume(ctx, data, directions=((1, 0, 0), (0, 1, 0)))


def test_camera_orbit_around_a_centre(ctx):
    c0 = umbra.Camera.orbit((0, 0, 1), 10)
    c1 = umbra.Camera.orbit((0, 0, 1), 10, center=(5, 6, 7))
    assert c1.target == (5.0, 6.0, 7.0)
    assert np.allclose(np.subtract(c1.eye, c1.target), np.subtract(c0.eye, c0.target))


def test_nifti_affine_as_the_readme_says_matches_umbras_loader(ctx, tmp_path):
    nib = pytest.importorskip("nibabel")
    rng = np.random.default_rng(3)
    xyz = rng.integers(-1000, 2000, (5, 6, 7)).astype(np.int16)   # nibabel's (x, y, z)
    # LPS-like flips, a rotation about z and anisotropic voxels, away from the origin
    c, s = np.cos(0.3), np.sin(0.3)
    rot = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]) @ np.diag([-1, -1, 1])
    affine = np.eye(4)
    affine[:3, :3] = rot @ np.diag([0.9, 1.1, 2.5])
    affine[:3, 3] = (12.5, -30, 4)
    path = tmp_path / "w.nii.gz"
    nib.save(nib.Nifti1Image(xyz, affine), path)
    img = nib.load(path)
    A = img.affine
    spacing = np.linalg.norm(A[:3, :3], axis=0)          # column a = index axis a = x, y, z
    with umbra.Volume(ctx, np.ascontiguousarray(np.asanyarray(img.dataobj).T),
                      spacing=tuple(spacing), origin=tuple(A[:3, 3]),
                      directions=(A[:3, :3] / spacing).T) as mine, \
            ctx.load_volume(str(path)) as theirs:
        a, b = mine.info, theirs.info
        assert a.dims == b.dims == (5, 6, 7)
        assert np.allclose(a.spacing, b.spacing, rtol=1e-6)
        assert np.allclose(a.origin, b.origin, atol=1e-5)
        assert np.allclose(a.directions, b.directions, atol=1e-6)
        assert np.allclose(a.center, b.center, atol=1e-4)
        assert a.value_range == b.value_range
        # and the centre is where the affine puts the middle index
        mid = A @ np.array([2, 2.5, 3, 1.0])
        assert np.allclose(a.center, mid[:3], atol=1e-4)
