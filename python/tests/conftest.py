# SPDX-License-Identifier: Apache-2.0
"""Shared fixtures of the Python package's tests: one OpenCL context for the session (PoCL's
first context is slow to make), the repository root, the C command-line tool to compare with, and
a reader for the EXR files it writes."""

import os
import pathlib

import numpy as np
import pytest

import umbra

REPO = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def ctx():
    with umbra.Context() as c:
        yield c


@pytest.fixture(scope="session")
def cli():
    """build/umbra-render, or $UMBRA_RENDER. CI sets UMBRA_RENDER, and then a missing tool fails
    the test instead of skipping it."""
    given = os.environ.get("UMBRA_RENDER")
    path = pathlib.Path(given) if given else REPO / "build" / "umbra-render"
    if not os.access(path, os.X_OK):
        if given:
            pytest.fail(f"UMBRA_RENDER={given} is not an executable")
        pytest.skip(f"{path} is not built (cmake --build build, or set UMBRA_RENDER)")
    return path


@pytest.fixture(scope="session")
def read_exr(ctx):
    """Reads an EXR (umbra-render's output) as (H, W, 4) float32: through umbra's own reader where
    the package has image I/O (a source build with OpenImageIO), else with the OpenEXR package
    from PyPI (the wheel, which has none)."""
    if umbra.has_image_io:
        return lambda path: ctx.read_image(str(path))
    OpenEXR = pytest.importorskip("OpenEXR", reason="this umbra has no image I/O and the OpenEXR "
                                  "package is not installed to read umbra-render's EXR files")

    def read(path):
        with OpenEXR.File(str(path)) as f:
            return np.array(f.channels()["RGBA"].pixels, dtype=np.float32)
    return read
