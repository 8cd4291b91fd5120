# SPDX-License-Identifier: Apache-2.0
"""Volume.from_nibabel, from_sitk and from_vtk: volumes from the image objects of nibabel,
SimpleITK and VTK (pyvista.ImageData is a vtkImageData), with their spacing, origin and direction.

Each library has its own index-to-world map; each is taken apart into umbra's (the README's
"World coordinates"): voxel data[k, j, i] lies at origin + i*sx*d[0] + j*sy*d[1] + k*sz*d[2],
origin the centre of voxel (0, 0, 0), d[a] the world direction of index axis a (a row).

- nibabel: world = A @ (i, j, k, 1) with the affine A (RAS+): spacing |A[:3, a]|, origin
  A[:3, 3], d = (A[:3, :3] / spacing).T, as umbra's NIfTI loader does it; the voxels are
  ``dataobj`` as nibabel scales it (float64 for a file with scl_slope/scl_inter).
- SimpleITK: world = origin + D @ (spacing * index) with the direction matrix D (row-major in
  GetDirection(), column a is index axis a): d = D.T.
- VTK: the same as ITK with GetDirectionMatrix(), and an extent whose first index may not be 0;
  point data are the voxels, or cell data, whose voxels are the cells' centres.

Nothing here interprets voxels: the arrays go to the Volume constructor, which converts a dtype
umbra does not store once, on the host.
"""

import numpy as np

from . import _umbra


def _invalid(message):
    """umbra.Error with status ERROR_INVALID_ARGUMENT, as the compiled module raises it."""
    status = _umbra.Status.ERROR_INVALID_ARGUMENT
    err = _umbra.Error(f"UMBRA_{status.name}: {message}")
    err.status = status
    err.message = message
    return err


def _volume(context, zyx, spacing, origin, directions, kwargs):
    return _umbra.Volume(context, np.ascontiguousarray(zyx),
                         spacing=tuple(float(s) for s in spacing),
                         origin=tuple(float(o) for o in origin),
                         directions=[tuple(float(v) for v in row) for row in directions],
                         **kwargs)


def _three_d(shape, what):
    """The index of the first three axes, dropping trailing axes of size 1, or umbra.Error."""
    shape = tuple(int(n) for n in shape)
    if len(shape) < 3 or any(n != 1 for n in shape[3:]):
        raise _invalid(f"{what}: image of shape {shape} is not 3-D (axes past the third must be "
                       "of size 1; pick one volume of a time series or channel first)")
    return (slice(None),) * 3 + (0,) * (len(shape) - 3)


def from_nibabel(context, image, **kwargs):
    what = "umbra.Volume.from_nibabel"
    if not (hasattr(image, "dataobj") and hasattr(image, "affine")):
        raise _invalid(f"{what}: a {type(image).__name__} is not a nibabel image "
                       "(no dataobj and affine)")
    index = _three_d(image.shape, what)
    A = image.affine
    if A is None:
        A = image.header.get_best_affine()
    A = np.asarray(A, dtype=np.float64)
    xyz = np.asanyarray(image.dataobj)[index]
    # |column a|, rounded to float32 before the division, as umbra's NIfTI loader does, so that
    # the directions come out bit for bit as umbra-render's for the same file
    spacing = np.linalg.norm(A[:3, :3], axis=0).astype(np.float32)
    if not np.all(spacing > 0):
        raise _invalid(f"{what}: the affine's columns {A[:3, :3].T.tolist()} must be non-zero")
    # nibabel's (x, y, z) arrays are Fortran-ordered: their transpose is (z, y, x) in place
    return _volume(context, xyz.T, spacing, A[:3, 3], (A[:3, :3] / spacing).T, kwargs)


def from_sitk(context, image, **kwargs):
    what = "umbra.Volume.from_sitk"
    import SimpleITK as sitk

    if not isinstance(image, sitk.Image):
        raise _invalid(f"{what}: a {type(image).__name__} is not a SimpleITK.Image")
    if image.GetDimension() != 3:
        raise _invalid(f"{what}: the image is {image.GetDimension()}-D, not 3-D")
    if image.GetNumberOfComponentsPerPixel() != 1:
        raise _invalid(f"{what}: the image has {image.GetNumberOfComponentsPerPixel()} "
                       "components per voxel; pass one (SimpleITK.VectorIndexSelectionCast)")
    zyx = sitk.GetArrayViewFromImage(image)          # (z, y, x), a view of the image's buffer
    D = np.array(image.GetDirection(), dtype=np.float64).reshape(3, 3)
    return _volume(context, zyx, image.GetSpacing(), image.GetOrigin(), D.T, kwargs)


def _vtk_values(image, array, what):
    """(values, on_cells): the named array, or the active scalars, or the only array, of the
    point data first, then of the cell data."""
    point, cell = image.GetPointData(), image.GetCellData()

    def names(data):
        return [data.GetArrayName(i) for i in range(data.GetNumberOfArrays())]

    for data, on_cells in ((point, False), (cell, True)):
        if array is not None:
            found = data.GetArray(array)
        else:
            found = data.GetScalars()
            if found is None and data.GetNumberOfArrays() == 1:
                found = data.GetArray(0)
        if found is not None:
            return found, on_cells
    raise _invalid(f"{what}: " + (f"no point or cell array named {array!r}" if array is not None
                                  else "no point or cell scalars to choose")
                   + f" (point arrays {names(point)}, cell arrays {names(cell)}); name one with "
                   "array=")


def from_vtk(context, image, array=None, **kwargs):
    what = "umbra.Volume.from_vtk"
    if not (hasattr(image, "GetExtent") and hasattr(image, "GetPointData")):
        raise _invalid(f"{what}: a {type(image).__name__} is not a vtkImageData")
    from vtkmodules.util.numpy_support import vtk_to_numpy

    values, on_cells = _vtk_values(image, array, what)
    if values.GetNumberOfComponents() != 1:
        raise _invalid(f"{what}: array {values.GetName()!r} has {values.GetNumberOfComponents()} "
                       "components; pass a one-component array")
    x0, x1, y0, y1, z0, z1 = image.GetExtent()
    dims = np.array([x1 - x0 + 1, y1 - y0 + 1, z1 - z0 + 1])
    first = np.array([x0, y0, z0], dtype=np.float64)
    if on_cells:
        # a cell spans two points along an axis of more than one point, and is the point itself
        # along an axis of one
        first += np.where(dims > 1, 0.5, 0.0)
        dims = np.maximum(dims - 1, 1)
    data = vtk_to_numpy(values)
    if data.size != int(np.prod(dims)):
        raise _invalid(f"{what}: array {values.GetName()!r} has {data.size} values for "
                       f"{' x '.join(map(str, dims))} {'cells' if on_cells else 'points'}")
    spacing = np.array(image.GetSpacing(), dtype=np.float64)
    m = image.GetDirectionMatrix()
    D = np.array([[m.GetElement(r, c) for c in range(3)] for r in range(3)])
    origin = np.array(image.GetOrigin(), dtype=np.float64) + D @ (spacing * first)
    # VTK orders points x fastest: C order (z, y, x)
    zyx = data.reshape(dims[2], dims[1], dims[0])
    return _volume(context, zyx, spacing, origin, D.T, kwargs)
