# SPDX-License-Identifier: Apache-2.0
"""Volume.from_nibabel, from_sitk and from_vtk against the libraries themselves: every voxel
lands where the library's own index-to-world map puts it (nibabel's affine, SimpleITK's and VTK's
TransformIndexToPhysicalPoint), and the volume draws what umbra's C readers draw from the same
file (NIfTI, MetaImage). Each library's tests skip when it is not installed; CI installs all of
them in the venv that tests the wheel (.ci/wheel.sh)."""

import os
import subprocess

import numpy as np
import pytest

import umbra

from conftest import REPO
from test_formats import CLI_BACKGROUND, CLI_CAMERA_DIR, CLI_LIGHT_DIR

W, H = 64, 48
CT_BONE = REPO / "examples" / "presets" / "ct_bone.json"


def world(info, index):
    """umbra's map: origin + sum over a of index[a] * spacing[a] * directions[a]."""
    return np.asarray(info.origin) + (np.asarray(index, float) * info.spacing) @ \
        np.asarray(info.directions)


def corners(dims):
    return [(i, j, k) for i in (0, dims[0] - 1) for j in (0, dims[1] - 1) for k in (0, dims[2] - 1)]


def rotation(a, b):
    """A proper rotation about z by a, then about x by b; not symmetric, so that a transposed
    direction matrix shows."""
    ca, sa, cb, sb = np.cos(a), np.sin(a), np.cos(b), np.sin(b)
    return np.array([[1, 0, 0], [0, cb, -sb], [0, sb, cb]]) @ \
        np.array([[ca, -sa, 0], [sa, ca, 0], [0, 0, 1]])


def hu_volume(nx=22, ny=18, nz=14):
    """(z, y, x) float64 'CT' in Hounsfield units: a bone shell, soft tissue, a dense blob off
    centre."""
    z, y, x = np.mgrid[-1:1:nz * 1j, -1:1:ny * 1j, -1:1:nx * 1j]
    r = np.sqrt(x * x + (1.2 * y) ** 2 + z * z)
    hu = np.where(r < 0.85, 40.0, -1000.0) + np.where((r > 0.65) & (r < 0.85), 900.0, 0.0)
    return hu + 600 * np.exp(-((x - 0.3) ** 2 + y ** 2 + z ** 2) / 0.03)


def render(ctx, vol, tf, technique="cssm"):
    info = vol.info
    camera = umbra.Camera.orbit(CLI_CAMERA_DIR, info.diagonal, 30, center=info.center)
    with umbra.Renderer(ctx, vol, tf, camera=camera,
                        light=umbra.Light.directional(CLI_LIGHT_DIR)) as r:
        r.set_options(ground_plane=True, background=CLI_BACKGROUND)
        return r.render(W, H, technique=technique)


def cli_render(cli, tmp_path, volume_path, read_exr):
    exr = tmp_path / "cli.exr"
    env = dict(os.environ)
    env.setdefault("POCL_CACHE_DIR", str(tmp_path / "pocl-cache"))
    subprocess.run([str(cli), "--volume", str(volume_path), "--tf", str(CT_BONE), "--technique",
                    "cssm", "--size", f"{W}x{H}", "--out", str(exr)],
                   check=True, env=env, capture_output=True)
    return read_exr(exr)


# ---- nibabel ------------------------------------------------------------------------------------

def write_scaled_nifti(path):
    """A NIfTI whose int16 voxels carry scl_slope and scl_inter (nibabel picks them to store the
    float64 HU values), so that nibabel's dataobj is float64."""
    nib = pytest.importorskip("nibabel")
    A = np.eye(4)
    A[:3, :3] = rotation(0.4, -0.3) @ np.diag([-0.9, 0.8, 1.3])
    A[:3, 3] = (40.0, -25.0, 60.0)
    img = nib.Nifti1Image(np.asfortranarray(hu_volume().T), A)
    img.set_data_dtype(np.int16)
    nib.save(img, path)
    return A


def test_nibabel_float64_nifti_renders_as_the_cli_renders_the_file(ctx, cli, read_exr, tmp_path):
    nib = pytest.importorskip("nibabel")
    nii = tmp_path / "scaled.nii.gz"
    A = write_scaled_nifti(nii)
    img = nib.load(nii)
    slope, inter = img.dataobj.slope, img.dataobj.inter
    assert (slope, inter) != (1.0, 0.0)                     # a scaled file ...
    assert np.asanyarray(img.dataobj).dtype == np.float64   # ... whose dataobj is float64
    with umbra.Volume.from_nibabel(ctx, img) as mine, ctx.load_volume(str(nii)) as theirs:
        a, b = mine.info, theirs.info
        assert mine.shape == (14, 18, 22)
        for k in ("dims", "spacing", "origin", "directions", "value_range"):
            assert getattr(a, k) == getattr(b, k), k
        assert a.value_range[0] == pytest.approx(-1000, abs=abs(slope))
        for ijk in corners(a.dims):
            assert np.allclose(world(a, ijk), nib.affines.apply_affine(A, ijk), atol=1e-4)
        with ctx.load_transfer_function(str(CT_BONE)) as tf:
            py = render(ctx, mine, tf)
    c = cli_render(cli, tmp_path, nii, read_exr)
    assert py.shape == c.shape == (H, W, 4)
    assert np.max(np.abs(py - c)) <= 1e-6
    assert np.ptp(py[..., :3]) > 0.2


def test_nibabel_shapes(ctx):
    nib = pytest.importorskip("nibabel")
    data = np.arange(4 * 5 * 6, dtype=np.int16).reshape(4, 5, 6, order="F")
    A = np.diag([2.0, 3.0, 4.0, 1.0])
    with umbra.Volume.from_nibabel(ctx, nib.Nifti1Image(data[..., None], A)) as v:
        assert v.shape == (6, 5, 4) and v.info.spacing == (2, 3, 4)
        assert v.info.value_range == (0, 119)
    with pytest.raises(umbra.Error, match=r"from_nibabel: image of shape \(4, 5, 6, 2\) is not "
                                          "3-D") as e:
        umbra.Volume.from_nibabel(ctx, nib.Nifti1Image(np.stack([data, data], -1), A))
    assert e.value.status == umbra.Status.ERROR_INVALID_ARGUMENT
    with pytest.raises(umbra.Error, match=r"shape \(4, 5\) is not 3-D"):
        umbra.Volume.from_nibabel(ctx, nib.Nifti1Image(data[:, :, 0], A))
    with pytest.raises(umbra.Error, match="use umbra.Volume.from_nibabel"):
        umbra.Volume(ctx, nib.Nifti1Image(data, A))
    with pytest.raises(umbra.Error, match="a ndarray is not a nibabel image"):
        umbra.Volume.from_nibabel(ctx, data)


# ---- SimpleITK ----------------------------------------------------------------------------------

def sitk_image(sitk):
    """An int32 SimpleITK image (z, y, x) with anisotropic spacing, an origin and a rotation."""
    img = sitk.GetImageFromArray(np.round(hu_volume()).astype(np.int32))
    img.SetSpacing((0.7, 0.8, 1.9))
    img.SetOrigin((-12.0, 30.5, 4.25))
    img.SetDirection(tuple(rotation(0.5, 0.2).ravel()))
    return img


def test_sitk_image_lands_where_itk_puts_it_and_draws_as_its_metaimage(ctx, tmp_path):
    sitk = pytest.importorskip("SimpleITK")
    img = sitk_image(sitk)
    mha = tmp_path / "x.mha"
    sitk.WriteImage(sitk.Cast(img, sitk.sitkInt16), str(mha))
    with umbra.Volume.from_sitk(ctx, img) as mine, ctx.load_volume(str(mha)) as theirs:
        a, b = mine.info, theirs.info
        assert mine.shape == (14, 18, 22) and a.dims == b.dims == img.GetSize()
        # int32 values in -1000..1500 are stored as int16: 2 bytes a voxel, like the int16 file
        assert a.device_bytes == b.device_bytes
        assert a.value_range == b.value_range == (-1000.0, float(np.round(hu_volume()).max()))
        for ijk in corners(a.dims):
            assert np.allclose(world(a, ijk), img.TransformIndexToPhysicalPoint(ijk), atol=1e-4)
        assert np.allclose(a.origin, b.origin, atol=1e-5)
        assert np.allclose(a.directions, b.directions, atol=1e-6)
        with ctx.load_transfer_function(str(CT_BONE)) as tf:
            assert np.max(np.abs(render(ctx, mine, tf) - render(ctx, theirs, tf))) <= 1e-5


def test_sitk_refuses_what_is_not_a_scalar_volume(ctx):
    sitk = pytest.importorskip("SimpleITK")
    with pytest.raises(umbra.Error, match="2-D, not 3-D"):
        umbra.Volume.from_sitk(ctx, sitk.Image(4, 4, sitk.sitkFloat32))
    with pytest.raises(umbra.Error, match="3 components per voxel"):
        umbra.Volume.from_sitk(ctx, sitk.Image([4, 4, 4], sitk.sitkVectorFloat32, 3))
    with pytest.raises(umbra.Error, match="use umbra.Volume.from_sitk"):
        umbra.Volume(ctx, sitk_image(sitk))


# ---- VTK and pyvista ----------------------------------------------------------------------------

def vtk_point(image, ijk):
    """VTK's own map of a structured index (extent-based) to the world."""
    out = [0.0, 0.0, 0.0]
    image.TransformIndexToPhysicalPoint(*(int(v) for v in ijk), out)
    return np.array(out)


def vtk_reference(ctx, image, zyx):
    """The volume built by hand from VTK's own index-to-world map of the first voxel and its
    neighbours along each axis."""
    x0, _, y0, _, z0, _ = image.GetExtent()
    p0 = vtk_point(image, (x0, y0, z0))
    steps = [vtk_point(image, np.add((x0, y0, z0), e)) - p0 for e in np.eye(3, dtype=int)]
    spacing = [float(np.linalg.norm(s)) for s in steps]
    return umbra.Volume(ctx, np.ascontiguousarray(zyx, np.float32), spacing=spacing,
                        origin=tuple(p0), directions=[s / n for s, n in zip(steps, spacing)])


def test_vtk_image_data_with_extent_and_direction(ctx):
    vtk = pytest.importorskip("vtkmodules.vtkCommonDataModel")
    from vtkmodules.util.numpy_support import numpy_to_vtk

    zyx = hu_volume()
    image = vtk.vtkImageData()
    image.SetExtent(3, 3 + 21, -2, -2 + 17, 5, 5 + 13)   # the first index is not 0
    image.SetSpacing(0.9, 1.1, 1.7)
    image.SetOrigin(-12.0, 30.5, 4.25)
    image.SetDirectionMatrix(*rotation(-0.6, 0.35).ravel())
    arr = numpy_to_vtk(zyx.ravel(), deep=True)         # float64, x fastest
    arr.SetName("hu")
    image.GetPointData().SetScalars(arr)
    with umbra.Volume.from_vtk(ctx, image) as mine, vtk_reference(ctx, image, zyx) as ref:
        a = mine.info
        assert mine.shape == zyx.shape and a.value_range == ref.info.value_range
        x0, _, y0, _, z0, _ = image.GetExtent()
        for ijk in corners(a.dims):
            assert np.allclose(world(a, ijk), vtk_point(image, np.add(ijk, (x0, y0, z0))),
                               atol=1e-4)
        tf = umbra.TransferFunction.load_paraview(ctx, str(CT_BONE))
        assert np.max(np.abs(render(ctx, mine, tf) - render(ctx, ref, tf))) <= 1e-5
    with pytest.raises(umbra.Error, match="use umbra.Volume.from_vtk"):
        umbra.Volume(ctx, image)


def test_pyvista_point_and_cell_data(ctx):
    pv = pytest.importorskip("pyvista")
    zyx = np.round(hu_volume()).astype(np.int32)
    nz, ny, nx = zyx.shape
    direction = rotation(0.3, 0.1)
    spacing, origin = (0.5, 0.75, 1.25), (1.0, -2.0, 3.0)
    points = pv.ImageData(dimensions=(nx, ny, nz), spacing=spacing, origin=origin,
                          direction_matrix=direction)
    points.point_data["density"] = zyx.ravel()          # x fastest: VTK's order
    cells = pv.ImageData(dimensions=(nx + 1, ny + 1, nz + 1), spacing=spacing, origin=origin,
                         direction_matrix=direction)
    cells.cell_data["density"] = zyx.ravel()
    centres = cells.cell_centers().points
    with umbra.Volume.from_vtk(ctx, points) as p, umbra.Volume.from_vtk(ctx, cells) as c:
        assert p.shape == c.shape == zyx.shape
        assert p.info.value_range == c.info.value_range == (zyx.min(), zyx.max())
        for ijk in corners(p.info.dims):
            assert np.allclose(world(p.info, ijk), vtk_point(points, ijk), atol=1e-4)
            # cell data: each voxel is its cell's centre (VTK numbers cells x fastest)
            n = ijk[0] + nx * (ijk[1] + ny * ijk[2])
            assert np.allclose(world(c.info, ijk), centres[n], atol=1e-4)
        # the same voxels, the cell grid's half a voxel further along each axis: seen from the
        # same offset to each box's centre, under the same light, the two pictures are one
        half = (np.asarray(spacing) / 2) @ np.asarray(direction).T
        assert np.allclose(np.subtract(c.info.center, p.info.center), half, atol=1e-5)
        with ctx.load_transfer_function(str(CT_BONE)) as tf:
            a, b = render(ctx, p, tf), render(ctx, c, tf)
            assert np.max(np.abs(a - b)) <= 1e-4 and np.ptp(a[..., :3]) > 0.2


def test_vtk_array_choice(ctx):
    pv = pytest.importorskip("pyvista")
    grid = pv.ImageData(dimensions=(4, 5, 6))
    grid.point_data["a"] = np.arange(120, dtype=np.float32)
    grid.point_data["b"] = np.full(120, 7, np.uint8)
    grid.point_data["rgb"] = np.zeros((120, 3), np.float32)
    grid.set_active_scalars(None)
    with pytest.raises(umbra.Error, match=r"no point or cell scalars to choose \(point arrays "
                                          r"\['a', 'b', 'rgb'\]"):
        umbra.Volume.from_vtk(ctx, grid)
    with umbra.Volume.from_vtk(ctx, grid, array="a") as v:
        assert v.shape == (6, 5, 4) and v.info.value_range == (0, 119)
    with umbra.Volume.from_vtk(ctx, grid, array="b", value_range=(0, 10)) as v:
        assert v.info.value_range == (0, 10)
    with pytest.raises(umbra.Error, match="'rgb' has 3 components"):
        umbra.Volume.from_vtk(ctx, grid, array="rgb")
    with pytest.raises(umbra.Error, match="no point or cell array named 'c'"):
        umbra.Volume.from_vtk(ctx, grid, array="c")
