# SPDX-License-Identifier: Apache-2.0
"""File names from Python (#29 item 6): a path holding a NUL character is refused with ValueError
naming the function and the argument, never cut at the NUL (before, "a.png\\x00.txt" wrote
a.png)."""

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
    ctx.write_image(str(tmp_path / "ok.png"), np.ones((2, 2, 4), np.float32))
    assert (tmp_path / "ok.png").stat().st_size > 0


def test_write_image_with_nul_writes_nothing(ctx, tmp_path):
    with pytest.raises(ValueError, match="umbra.Context.write_image: path"):
        ctx.write_image(str(tmp_path / NUL), np.zeros((2, 2, 4), np.float32))
    assert list(tmp_path.iterdir()) == []
