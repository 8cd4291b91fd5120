# SPDX-License-Identifier: Apache-2.0
"""umbra: shadows in direct volume rendering, on OpenCL, from NumPy.

A binding of the umbra C library (``umbra/umbra.h``) made with nanobind. Arrays go in and out
without copies where the C API allows: a volume is read in place from a C-contiguous array of
shape (z, y, x) and copied once, to the device; ``Renderer.render`` returns a new (or fills your)
``(height, width, 4)`` float32 array of premultiplied RGBA.

    import numpy as np, umbra
    with umbra.Context() as ctx:
        scene = umbra.Scene(ctx, "spheres")
        with scene.renderer() as r:
            img = r.render(256, 256, technique="cssm", taps=7)
        umbra.Image(img)   # in a notebook, a cell ending in this shows the picture

Arrays of any real, integer or bool dtype are accepted (uint8, uint16, int16 and float32 as they
are, others converted once: see :class:`Volume`); ``Volume.from_nibabel``, ``from_sitk`` and
``from_vtk`` take those libraries' images with their placement. Installed from the wheel
(``pip install umbra-dvr``) umbra uses the system's OpenCL drivers, else PoCL from PyPI
(``pip install 'umbra-dvr[pocl]'``); the wheel has no PNG/EXR I/O (``has_image_io``):
:func:`to_srgb8` gives 8-bit pixels for Pillow or imageio.

Every failure raises :class:`umbra.Error`, whose ``status`` is an :class:`umbra.Status` and whose
``message`` is umbra's, naming the function and the value. Context, Volume, TransferFunction and
Renderer close deterministically (``with`` or ``close()``) and may be garbage-collected in any
order: each holds a reference on the C objects it needs.
"""

from . import _opencl

# Before the OpenCL loader's first call: the system's drivers, else PoCL from PyPI.
driver_from_pypi = _opencl.choose_drivers()
"""The PoCL library from PyPI (the ``pocl`` extra) the OpenCL loader was pointed at because the
system has no driver, or None (the system's drivers, or OCL_ICD_VENDORS as the user set it)."""

try:
    from ._umbra import (
        Camera,
        Context,
        Error,
        Interaction,
        Light,
        LightType,
        MAP_SIZE_AUTO,
        Projection,
        Renderer,
        RenderMode,
        RenderOptions,
        RenderStats,
        Sampler,
        Scene,
        ShadowOptions,
        Status,
        Technique,
        TransferFunction,
        Transmission,
        Volume,
        VolumeInfo,
        has_image_io,
        scene_names,
        technique_names,
        version,
    )
except ImportError as e:  # pragma: no cover - depends on how Python was started
    if "_umbra" not in str(e):
        raise
    raise ImportError(
        "umbra's compiled module is missing: this is the source folder python/umbra. Install the "
        "package (pip install ./python, see the README's Python section) and import it from "
        "outside python/."
    ) from e

from ._display import Image, install_reprs, show, to_srgb8

install_reprs(VolumeInfo, RenderStats)
del install_reprs

__version__: str = version()

__all__ = [
    "Camera",
    "Context",
    "Error",
    "Interaction",
    "Image",
    "Light",
    "LightType",
    "MAP_SIZE_AUTO",
    "Projection",
    "Renderer",
    "RenderMode",
    "RenderOptions",
    "RenderStats",
    "Sampler",
    "Scene",
    "ShadowOptions",
    "Status",
    "Technique",
    "TransferFunction",
    "Transmission",
    "Volume",
    "VolumeInfo",
    "driver_from_pypi",
    "has_image_io",
    "scene_names",
    "show",
    "technique_names",
    "to_srgb8",
    "version",
]
