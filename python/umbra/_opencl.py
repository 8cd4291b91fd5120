# SPDX-License-Identifier: Apache-2.0
"""Which OpenCL drivers the loader finds: the system's, else PoCL from PyPI.

The wheel carries the OpenCL ICD loader (ocl-icd), which loads the drivers that ICD files in
/etc/OpenCL/vendors name (or the folder $OPENCL_VENDOR_PATH). A machine without any gets a CPU
driver from PyPI with the ``pocl`` extra (``pip install 'umbra-dvr[pocl]'``): the package
pocl-binary-distribution, which pyopencl uses the same way. It installs
``<site-packages>/pyopencl/.libs/pocl.icd``, naming its library beside it; pyopencl's own loader
looks in that folder, a stock loader does not, so :func:`choose_drivers` points the loader at
that library through OCL_ICD_VENDORS (ocl-icd loads a file named there as the only driver;
OCL_ICD_FILENAMES says the same to the Khronos loader a source build may link). It runs when
umbra is imported, before the loader's first call reads the environment, and changes nothing
when OCL_ICD_VENDORS is set already or the system has a driver.
"""

import importlib.util
import os
import pathlib

SYSTEM_VENDORS = "/etc/OpenCL/vendors"


def system_vendors(environ):
    """The ICD files the loader would read without our help (none if the folder is missing)."""
    folder = environ.get("OPENCL_VENDOR_PATH") or SYSTEM_VENDORS
    try:
        return sorted(e.path for e in os.scandir(folder) if e.name.endswith(".icd"))
    except OSError:
        return []


def pypi_pocl():
    """The PoCL library pocl-binary-distribution installed, or None if it is not installed."""
    try:
        spec = importlib.util.find_spec("pocl_binary_distribution")
    except (ImportError, ValueError):
        return None
    if spec is None or not spec.origin:
        return None
    libs = pathlib.Path(spec.origin).resolve().parent.parent / "pyopencl" / ".libs"
    try:
        name = (libs / "pocl.icd").read_text().strip()
    except OSError:
        return None
    lib = libs / name           # the ICD file names the library relative to its own folder
    return lib if name and lib.is_file() else None


def choose_drivers(environ=os.environ):
    """Points the loader at PoCL from PyPI when no driver is named or installed; returns that
    library's path, or None when the environment was left as it was."""
    if environ.get("OCL_ICD_VENDORS") or environ.get("OCL_ICD_FILENAMES"):
        return None             # the user's choice
    if system_vendors(environ):
        return None
    lib = pypi_pocl()
    if lib is None:
        return None
    environ["OCL_ICD_VENDORS"] = str(lib)
    environ["OCL_ICD_FILENAMES"] = str(lib)
    return str(lib)
