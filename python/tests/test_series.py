# SPDX-License-Identifier: Apache-2.0
"""DICOM series and TIFF stacks from Python, written by independent writers (pydicom, Pillow):
ctx.load_volume reads a series directory (explicit and implicit VR, RLE Lossless), a list of its
files, and a multi-page TIFF; presets installed with the package are found by name, and
umbra-render --volume DIR/ --tf "Cool to Warm" renders the series."""

import subprocess

import numpy as np
import pytest

import umbra

NX, NY, NZ = 6, 5, 7


def hu(shape=(NZ, NY, NX)):
    """(z, y, x) Hounsfield values, distinct everywhere."""
    k, j, i = np.indices(shape)
    return (10 * i + 100 * j + 1000 * k - 3000).astype(np.float64)


def write_series(directory, syntax, order=(4, 1, 6, 0, 3, 5, 2)):
    """A CT series in shuffled file order: rows along +y, columns along -z (normal -x), pixel
    spacing 0.7 (rows) by 0.9 (columns), slices 2.5 apart, stored as HU + 1024, intercept -1024."""
    pydicom = pytest.importorskip("pydicom")
    from pydicom.dataset import FileDataset, FileMetaDataset
    directory.mkdir()
    values = hu()
    for n, k in enumerate(order):
        meta = FileMetaDataset()
        meta.MediaStorageSOPClassUID = "1.2.840.10008.5.1.4.1.1.2"
        meta.MediaStorageSOPInstanceUID = f"1.2.826.0.1.3680043.2.1125.5.{k + 1}"
        meta.TransferSyntaxUID = syntax
        ds = FileDataset(str(directory / f"slice{n}"), {}, file_meta=meta, preamble=b"\0" * 128)
        ds.SOPClassUID = meta.MediaStorageSOPClassUID
        ds.SOPInstanceUID = meta.MediaStorageSOPInstanceUID
        ds.Modality = "CT"
        ds.SeriesInstanceUID = "1.2.826.0.1.3680043.2.1125.5.100"
        ds.Rows, ds.Columns = NY, NX
        ds.SamplesPerPixel = 1
        ds.PhotometricInterpretation = "MONOCHROME2"
        ds.BitsAllocated, ds.BitsStored, ds.HighBit, ds.PixelRepresentation = 16, 16, 15, 1
        ds.ImageOrientationPatient = [0, 1, 0, 0, 0, -1]
        ds.ImagePositionPatient = [12.5 - 2.5 * k, -40.25, 7.0]
        ds.PixelSpacing = [0.7, 0.9]
        ds.SliceThickness = 3
        ds.RescaleIntercept, ds.RescaleSlope = -1024, 1
        pixels = (values[k] + 1024).astype(np.int16)
        ds.is_little_endian = True
        ds.is_implicit_VR = syntax == pydicom.uid.ImplicitVRLittleEndian
        ds.PixelData = pixels.tobytes()
        if syntax == pydicom.uid.RLELossless:
            ds.compress(syntax, pixels)
        ds.save_as(str(directory / f"slice{n}"), write_like_original=False)
    return sorted(str(p) for p in directory.iterdir())


@pytest.mark.parametrize("syntax", ["1.2.840.10008.1.2.1", "1.2.840.10008.1.2",
                                    "1.2.840.10008.1.2.5"])
def test_dicom_series_from_pydicom(ctx, tmp_path, syntax):
    files = write_series(tmp_path / "ct", syntax)
    for vol in (ctx.load_volume(str(tmp_path / "ct")), ctx.load_volume(files)):
        i = vol.info
        assert i.dims == (NX, NY, NZ)
        assert i.spacing == pytest.approx((0.9, 0.7, 2.5))
        assert i.transform_given and i.origin == pytest.approx((12.5, -40.25, 7.0))
        assert np.allclose(i.directions, [[0, 1, 0], [0, 0, -1], [-1, 0, 0]])
        assert i.value_range == pytest.approx((-3000.0, hu().max()))


def test_tiff_stack_from_pillow(ctx, tmp_path):
    Image = pytest.importorskip("PIL.Image")
    k, j, i = np.indices((4, 5, 6))
    stack = (7 * i + 300 * j + 1000 * k).astype(np.uint16)
    pages = [Image.fromarray(page) for page in stack]
    path = tmp_path / "stack.tif"
    pages[0].save(path, save_all=True, append_images=pages[1:], compression="tiff_lzw")
    i = ctx.load_volume(str(path)).info
    assert i.dims == (6, 5, 4)
    assert i.value_range == (0.0, float(stack.max()))


def test_preset_by_name_and_cli_match(ctx, cli, tmp_path):
    write_series(tmp_path / "ct", "1.2.840.10008.1.2.1")
    tf = ctx.load_transfer_function("Cool to Warm")
    assert tuple(tf.table[0, :3]) == pytest.approx((0.231373, 0.298039, 0.752941), abs=1e-4)
    out = tmp_path / "cli.png"
    subprocess.run([str(cli), "--volume", f"{tmp_path / 'ct'}/", "--tf", "Cool to Warm",
                    "--technique", "cssm", "--size", "40x32", "--out", str(out)], check=True,
                   stderr=subprocess.DEVNULL)
    Image = pytest.importorskip("PIL.Image")
    rgb = np.asarray(Image.open(out).convert("RGB"), dtype=np.float64)
    assert rgb.shape == (32, 40, 3)
    assert np.abs(rgb[16, 20] - rgb[0, 0]).sum() > 10  # the lit series, not the background
