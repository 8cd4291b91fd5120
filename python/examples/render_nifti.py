#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Renders a NIfTI volume (read with nibabel) with shadows into a PNG.

    python render_nifti.py head.nii.gz head.png --technique cssm
    python render_nifti.py ct.nii.gz ct.png --tf ../../examples/presets/ct_bone.json
    python render_nifti.py --make-demo demo.nii.gz     # writes a small synthetic CT-like volume

umbra.Volume.from_nibabel takes the image as nibabel reads it: the voxels of its dataobj (an
(x, y, z) array in Fortran order, i.e. x varying fastest in memory, which is umbra's layout, so
its transpose goes to the device without a copy in Python; a scaled image, with scl_slope or
scl_inter, comes as float64 and is converted to float32 once) and the placement in the file's
world (RAS+, millimetres) by its affine A, which maps a voxel index (i, j, k) = (x, y, z) to
A @ (i, j, k, 1), as umbra's own NIfTI loader does (the README's "Python" section spells the
mapping out). The camera orbits the box's world centre, volume.info.center. The picture is
written by umbra where it has image I/O, else (the wheel) as a PNG through Pillow with
umbra.to_srgb8. Ctrl-C stops a long render cleanly.
"""
import argparse
import sys

import nibabel as nib
import numpy as np

import umbra


def make_demo(path, n=64):
    """A small int16 'CT' in Hounsfield units: a skull-like shell around soft tissue with two
    denser inclusions, anisotropic voxels, saved as NIfTI-1."""
    z, y, x = np.mgrid[-1:1:n * 1j, -1:1:n * 1j, -1:1:n * 1j]
    r = np.sqrt(x * x + (y * 1.1) ** 2 + z * z)

    def inside(d, width=0.03):                              # smooth 0 -> 1 across a boundary
        return 1 / (1 + np.exp(-d / width))

    hu = -1000 + 1040 * inside(0.85 - r)                   # air, then soft tissue
    hu += 860 * inside(r - 0.72) * inside(0.85 - r)        # bone shell
    for c in ((0.3, 0.1, 0.0), (-0.25, -0.2, 0.2)):        # two denser inclusions
        hu += 260 * inside(0.17 - np.sqrt((x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2))
    xyz = np.asfortranarray(hu.astype(np.int16).T)         # nibabel's axis order: (x, y, z)
    # scanner-style placement: x and y flipped (LPS-stored data in RAS+), an origin off 0
    affine = np.diag([-0.9, -0.9, 1.2, 1.0])
    affine[:3, 3] = (28.8, 28.8, -38.4)
    img = nib.Nifti1Image(xyz, affine)
    nib.save(img, path)


def save(ctx, out, img):
    """Writes the render: .png or .exr through umbra, or a .png through Pillow where this umbra
    has no image I/O (the wheel)."""
    if umbra.has_image_io:
        ctx.write_image(out, img)
        return
    if not out.lower().endswith(".png"):
        raise SystemExit(f"{out}: this umbra writes no images itself; give a .png name "
                         "(written through Pillow)")
    from PIL import Image
    Image.fromarray(umbra.to_srgb8(img), "RGBA").save(out)


def show_progress(fraction):
    """A progress line on stderr; returning None lets the render go on (True would cancel)."""
    print(f"\r{100 * fraction:5.1f}%", end="" if fraction < 1 else "\n", file=sys.stderr)


def render(path, out, technique="cssm", size=(512, 512), light=(0.45, -1.0, 0.25), tf_path=None,
           **params):
    image = nib.load(path)
    with umbra.Context() as ctx:
        if tf_path:
            # a ParaView preset (or umbra's text format); a preset spans data values, e.g. HU
            vol = umbra.Volume.from_nibabel(ctx, image)
            tf = ctx.load_transfer_function(tf_path)
        else:
            lo, hi = np.percentile(np.asanyarray(image.dataobj), [1, 99.9])
            vol = umbra.Volume.from_nibabel(ctx, image, value_range=(float(lo), float(hi)))
            # low values clear, mid values faint and warm, the densest white and opaque
            tf = umbra.TransferFunction.from_points(ctx, [
                (0.00, 0.0, 0.0, 0.0, 0.0),
                (0.45, 0.8, 0.5, 0.4, 0.0),
                (0.55, 0.9, 0.6, 0.5, 0.04),
                (0.70, 1.0, 0.4, 0.3, 0.3),
                (0.85, 1.0, 0.95, 0.9, 0.05),
                (1.00, 1.0, 1.0, 1.0, 0.15)])
        info = vol.info
        camera = umbra.Camera.orbit((0.75, 0.5, 1.0), info.diagonal, center=info.center)
        with umbra.Renderer(ctx, vol, tf, camera=camera,
                            light=umbra.Light.directional(light)) as r:
            r.set_options(ground_plane=True, background=(0.08, 0.08, 0.1, 1.0))
            if sys.stderr.isatty():
                r.progress = show_progress
            try:
                img = r.render(size[0], size[1], technique=technique, **params)
            except KeyboardInterrupt:
                raise SystemExit("interrupted")
            s = r.stats
            print(f"{technique}: shadow build {s.shadow_build_ms:.1f} ms, render "
                  f"{s.render_ms:.1f} ms, {s.shadow_memory_bytes / 2**20:.1f} MiB", file=sys.stderr)
        save(ctx, out, img)
    return img


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("volume", help="a .nii or .nii.gz file")
    ap.add_argument("out", nargs="?", help="output .png or .exr")
    ap.add_argument("--make-demo", action="store_true", help="write a synthetic volume to VOLUME")
    ap.add_argument("--technique", default="cssm", choices=umbra.technique_names())
    ap.add_argument("--size", default="512x512", help="WxH")
    ap.add_argument("--tf", help="a ParaView preset .json (data units) or umbra .tf file")
    a = ap.parse_args()
    if a.make_demo:
        make_demo(a.volume)
        if not a.out:
            return
    if not a.out:
        ap.error("give an output file")
    w, h = (int(v) for v in a.size.split("x"))
    render(a.volume, a.out, a.technique, (w, h), tf_path=a.tf)
    print(f"wrote {a.out}", file=sys.stderr)


if __name__ == "__main__":
    main()
