# SPDX-License-Identifier: Apache-2.0
"""Shared fixtures of the Python package's tests: one OpenCL context for the session (PoCL's
first context is slow to make), the repository root, and the C command-line tool to compare with."""

import os
import pathlib

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
