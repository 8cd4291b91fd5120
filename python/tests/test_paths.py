# SPDX-License-Identifier: Apache-2.0
"""File names from Python (#29 items 1 and 6): a path holding a NUL character is refused with
ValueError naming the function and the argument, never cut at the NUL (before, "a.png\\x00.txt"
wrote a.png); and a header's detached data file must lie in the header's own directory unless
load_volume's data_roots allows where it lies."""

import numpy as np
import pytest

import umbra

NUL = "a.png\x00.txt"


def nul_calls(ctx, tmp_path):
    """(what the message names, a call with NUL in that path argument) for every function taking
    a path."""
    img = np.zeros((2, 2, 4), np.float32)
    bad = str(tmp_path / NUL)
    return [
        ("umbra.Context.load_volume: path", lambda: ctx.load_volume(bad)),
        ("umbra.Context.load_volume: data_roots entry",
         lambda: ctx.load_volume(str(tmp_path / "v.nhdr"), data_roots=[str(tmp_path), bad])),
        ("umbra.Context.load_transfer_function: path", lambda: ctx.load_transfer_function(bad)),
        ("umbra.TransferFunction.load_paraview: path", lambda: ctx.load_paraview(bad)),
        ("umbra.TransferFunction.load_paraview: path",
         lambda: umbra.TransferFunction.load_paraview(ctx, bad)),
        ("umbra.Context.write_image: path", lambda: ctx.write_image(bad, img)),
        ("umbra.Context.read_image: path", lambda: ctx.read_image(bad)),
        ("umbra.Context: cache_dir", lambda: umbra.Context(cache_dir=bad)),
    ]


def test_paths_with_nul_are_refused_naming_the_argument(ctx, tmp_path):
    (tmp_path / "a.png").write_bytes(b"")   # what a cut name would reach, for the readers
    for what, call in nul_calls(ctx, tmp_path):
        with pytest.raises(ValueError) as e:
            call()
        text = str(e.value)
        assert text.startswith(what + " "), (what, text)
        assert "contains a NUL character (at " in text and "a.png\\x00.txt" in text, text
    # Nothing was written under the cut name, and the context still works.
    assert (tmp_path / "a.png").read_bytes() == b""
    if umbra.has_image_io:
        ctx.write_image(str(tmp_path / "ok.png"), np.ones((2, 2, 4), np.float32))
        assert (tmp_path / "ok.png").stat().st_size > 0
    else:   # the wheel has no image I/O: show the context works by rendering
        with umbra.Scene(ctx, "spheres", 16).renderer() as r:
            assert r.render(8, 8)[..., 3].max() > 0


def test_write_image_with_nul_writes_nothing(ctx, tmp_path):
    with pytest.raises(ValueError, match="umbra.Context.write_image: path"):
        ctx.write_image(str(tmp_path / NUL), np.zeros((2, 2, 4), np.float32))
    assert list(tmp_path.iterdir()) == []


SECRET = bytes(range(40, 48))   # 2 x 2 x 2 uchar voxels, values 40..47


@pytest.fixture()
def layout(tmp_path):
    """hdr/ with headers naming ../outside/secret.raw (NRRD), its absolute path (MetaImage) and a
    link to it (Voreen .dat)."""
    hdr, outside = tmp_path / "hdr", tmp_path / "outside"
    hdr.mkdir()
    outside.mkdir()
    secret = outside / "secret.raw"
    secret.write_bytes(SECRET)
    (hdr / "link.raw").symlink_to(secret)
    (hdr / "up.nhdr").write_text("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\n"
                                 "encoding: raw\ndata file: ../outside/secret.raw\n")
    (hdr / "abs.mhd").write_text("NDims = 3\nDimSize = 2 2 2\nElementType = MET_UCHAR\n"
                                 f"ElementDataFile = {secret}\n")
    (hdr / "link.dat").write_text("ObjectFileName: link.raw\nResolution: 2 2 2\n"
                                  "SliceThickness: 1 1 1\nFormat: UCHAR\n")
    return hdr, outside


@pytest.mark.parametrize("name", ["up.nhdr", "abs.mhd", "link.dat"])
def test_load_volume_keeps_data_files_in_the_header_directory(ctx, layout, name):
    hdr, outside = layout
    with pytest.raises(umbra.Error) as e:
        ctx.load_volume(str(hdr / name))
    assert e.value.status == umbra.Status.ERROR_IO
    assert "secret.raw" in e.value.message and "the header's directory" in e.value.message
    with pytest.raises(umbra.Error, match="outside every data root given"):
        ctx.load_volume(str(hdr / name), data_roots=[str(hdr)])
    for roots in ([str(outside)], (str(hdr), str(outside)), ["/"]):
        with ctx.load_volume(str(hdr / name), data_roots=roots) as vol:
            assert vol.info.dims == (2, 2, 2)
            assert vol.info.value_range == (40.0, 47.0)   # the outside file's bytes


def test_data_roots_must_exist(ctx, layout):
    hdr, _ = layout
    with pytest.raises(umbra.Error, match="cannot be resolved") as e:
        ctx.load_volume(str(hdr / "up.nhdr"), data_roots=[str(hdr / "missing")])
    assert e.value.status == umbra.Status.ERROR_INVALID_ARGUMENT
    with pytest.raises(TypeError):
        ctx.load_volume(str(hdr / "up.nhdr"), data_roots=[1])
