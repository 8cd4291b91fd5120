# SPDX-License-Identifier: Apache-2.0
"""Which OpenCL driver umbra finds (umbra/_opencl.py): the system's ICD files, else PoCL from
PyPI (the pocl extra, pocl-binary-distribution), and never over the user's OCL_ICD_VENDORS. The
rule is tested on folders made here; the real PoCL from PyPI, where it is installed (CI's wheel
venv), in a child process whose loader sees no system driver."""

import json
import os
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import umbra
from umbra import _opencl


def fake_pocl_package(root, icd_text="libpocl-0123abcd.so\n"):
    """pocl-binary-distribution's layout: a package beside pyopencl/.libs/{pocl.icd, library}."""
    (root / "pocl_binary_distribution").mkdir(parents=True)
    (root / "pocl_binary_distribution" / "__init__.py").write_text("")
    libs = root / "pyopencl" / ".libs"
    libs.mkdir(parents=True)
    (libs / "pocl.icd").write_text(icd_text)
    (libs / icd_text.strip()).write_bytes(b"\x7fELF")
    return libs / icd_text.strip()


@pytest.fixture
def no_system(tmp_path):
    empty = tmp_path / "vendors"
    empty.mkdir()
    return {"OPENCL_VENDOR_PATH": str(empty)}


def test_pocl_from_pypi_when_the_system_has_no_driver(tmp_path, monkeypatch, no_system):
    lib = fake_pocl_package(tmp_path / "site")
    monkeypatch.syspath_prepend(str(tmp_path / "site"))
    env = dict(no_system)
    assert _opencl.choose_drivers(env) == str(lib.resolve())
    assert env["OCL_ICD_VENDORS"] == env["OCL_ICD_FILENAMES"] == str(lib.resolve())


def test_the_systems_driver_and_the_users_choice_come_first(tmp_path, monkeypatch, no_system):
    fake_pocl_package(tmp_path / "site")
    monkeypatch.syspath_prepend(str(tmp_path / "site"))
    vendors = tmp_path / "system"
    vendors.mkdir()
    (vendors / "README").write_text("not an ICD file")
    env = {"OPENCL_VENDOR_PATH": str(vendors)}
    assert _opencl.choose_drivers(env) is not None          # no .icd file: PoCL from PyPI
    (vendors / "vendor.icd").write_text("libvendor.so\n")
    env = {"OPENCL_VENDOR_PATH": str(vendors)}
    assert _opencl.choose_drivers(env) is None and "OCL_ICD_VENDORS" not in env
    for name in ("OCL_ICD_VENDORS", "OCL_ICD_FILENAMES"):
        env = dict(no_system, **{name: "/opt/my/driver.so"})
        assert _opencl.choose_drivers(env) is None
        assert env == dict(no_system, **{name: "/opt/my/driver.so"})


def test_nothing_is_set_without_pocl_from_pypi(tmp_path, monkeypatch, no_system):
    monkeypatch.setattr(_opencl, "pypi_pocl", lambda: None)
    env = dict(no_system)
    assert _opencl.choose_drivers(env) is None and env == no_system
    # a broken install (the ICD file names a library that is not there) counts as none
    lib = fake_pocl_package(tmp_path / "site")
    lib.unlink()
    monkeypatch.undo()
    monkeypatch.syspath_prepend(str(tmp_path / "site"))
    assert _opencl.pypi_pocl() is None


CHILD = textwrap.dedent("""
    import json, os, sys, numpy as np, umbra
    out = {"driver_from_pypi": umbra.driver_from_pypi}
    try:
        ctx = umbra.Context()
        out["device"] = ctx.device_name
        with umbra.Scene(ctx, "slab", 12).renderer() as r:
            out["pixels"] = r.render(12, 9, technique="reference").tolist()
    except umbra.Error as e:
        out["error"] = [e.status.name, e.message]
    maps = {l.split()[-1] for l in open("/proc/self/maps")}
    out["pocl_mapped"] = sorted(m for m in maps if os.path.basename(m).startswith("libpocl"))
    json.dump(out, sys.stdout)
""")


def child(env_changes, tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("OCL_ICD_VENDORS", "OCL_ICD_FILENAMES")}
    env.update(env_changes)
    env.setdefault("POCL_CACHE_DIR", str(tmp_path / "pocl-cache"))
    p = subprocess.run([sys.executable, "-c", CHILD], capture_output=True, text=True, env=env,
                       cwd=tmp_path, timeout=600)
    assert p.returncode == 0, p.stderr
    return json.loads(p.stdout)


def test_the_real_pocl_from_pypi_is_found_and_loaded(ctx, tmp_path, no_system):
    lib = _opencl.pypi_pocl()
    if lib is None:
        pytest.skip("pocl-binary-distribution is not installed (pip install 'umbra-dvr[pocl]')")
    got = child(no_system, tmp_path)
    assert got["driver_from_pypi"] == str(lib)
    assert got["pocl_mapped"] == [str(lib)], got["pocl_mapped"]   # that PoCL, not the system's
    assert got["device"].startswith("Portable Computing Language")
    if "error" in got:
        status, message = got["error"]
        if status == "ERROR_BUILD" and "unknown target CPU" in message:
            pytest.skip("PoCL 3.0 from PyPI (its LLVM) cannot compile for this CPU: "
                        + next(l for l in message.splitlines() if "unknown target CPU" in l))
        pytest.fail(f"{status}: {message}")
    with umbra.Scene(ctx, "slab", 12).renderer() as r:
        mine = r.render(12, 9, technique="reference")
    assert np.max(np.abs(np.array(got["pixels"], np.float32) - mine)) <= 1e-3


def test_the_users_empty_vendor_folder_is_respected(tmp_path, no_system):
    got = child(dict(no_system, OCL_ICD_VENDORS=no_system["OPENCL_VENDOR_PATH"]), tmp_path)
    assert got["driver_from_pypi"] is None and got["pocl_mapped"] == []
    assert got["error"][0] == "ERROR_NO_DEVICE"
