# SPDX-License-Identifier: Apache-2.0
"""The installed package: its version is the C project's, its type stubs are installed and parse,
and the option classes carry the C defaults (umbra_*_desc_init) in their docstrings."""

import ast
import pathlib
import re

import umbra

from conftest import REPO


def test_version_is_the_c_projects():
    cmake = (REPO / "CMakeLists.txt").read_text()
    assert umbra.__version__ == re.search(r"project\(umbra VERSION ([0-9.]+)", cmake).group(1)


def test_stub_is_installed_and_lists_every_class():
    stub = pathlib.Path(umbra.__file__).with_name("_umbra.pyi")
    tree = ast.parse(stub.read_text())
    classes = {n.name for n in tree.body if isinstance(n, ast.ClassDef)}
    # Image is Python (umbra/_display.py), typed in its source.
    exported = {n for n in umbra.__all__ if isinstance(getattr(umbra, n), type)} - {"Error", "Image"}
    assert exported <= classes, exported - classes
    assert (pathlib.Path(umbra.__file__).with_name("py.typed")).exists()


def test_docstrings_list_every_field_with_its_c_default():
    for cls in (umbra.ShadowOptions, umbra.RenderOptions):
        defaults = cls()
        for name in (n for n in dir(cls) if isinstance(getattr(cls, n), property)):
            assert f"    {name} (" in cls.__doc__, name
            assert f"default {getattr(defaults, name)!r})" in cls.__doc__, name
    assert f"map_size (int, default {umbra.ShadowOptions().map_size})" in umbra.Renderer.set_shadow.__doc__
