#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""Renders a NIfTI volume (read with nibabel) with shadows into a PNG.

    python render_nifti.py head.nii.gz head.png --technique cssm
    python render_nifti.py ct.nii.gz ct.png --tf ../../examples/presets/ct_bone.json
    python render_nifti.py --make-demo demo.nii.gz     # writes a small synthetic CT-like volume

nibabel hands the voxels over as an (x, y, z) array in Fortran order, i.e. x varying fastest in
memory, which is umbra's layout: its transpose is the C-contiguous (z, y, x) array umbra.Volume
takes, so the voxels go to the device without a copy in Python. A scaled image (scl_slope) is
read as float32 instead.

The volume is placed in the file's world (RAS+, millimetres) by its affine A, which maps a voxel
index (i, j, k) = (x, y, z) to A @ (i, j, k, 1). umbra takes it apart as umbra's own NIfTI loader
does: spacing[a] = |A[:3, a]| (column a is index axis a), origin = A[:3, 3] (voxel (0, 0, 0)'s
centre) and directions[a] = A[:3, a] / spacing[a], i.e. directions = (A[:3, :3] / spacing).T,
whose ROWS are the axes: the transposition turns nibabel's columns into umbra's rows. The
directions must be at right angles (a sheared affine raises umbra.Error ERROR_UNSUPPORTED). The
camera orbits the box's world centre, volume.info.center. Ctrl-C stops a long render cleanly.
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


def load_nifti(path):
    """(z, y, x) array for umbra and the placement: spacing (x, y, z), origin, directions."""
    img = nib.load(path)
    if img.ndim != 3:
        raise SystemExit(f"{path}: {img.ndim}-D image; a 3-D volume is needed")
    scaled = img.dataobj.slope != 1 or img.dataobj.inter != 0
    data = np.asanyarray(img.dataobj) if not scaled else img.get_fdata(dtype=np.float32)
    if data.dtype not in (np.uint8, np.uint16, np.int16, np.float32):
        data = data.astype(np.float32)
    # Fortran (x, y, z) -> C-contiguous (z, y, x) without copying; anything else is copied once.
    zyx = np.ascontiguousarray(data.T)
    A = img.affine
    # rounded to float32 before dividing, as umbra's loader does: the same numbers as umbra-render
    spacing = np.linalg.norm(A[:3, :3], axis=0).astype(np.float32)
    origin = tuple(float(v) for v in A[:3, 3])
    directions = (A[:3, :3] / spacing).T          # row a: the world direction of index axis a
    return zyx, tuple(float(v) for v in spacing), origin, directions


def show_progress(fraction):
    """A progress line on stderr; returning None lets the render go on (True would cancel)."""
    print(f"\r{100 * fraction:5.1f}%", end="" if fraction < 1 else "\n", file=sys.stderr)


def render(path, out, technique="cssm", size=(512, 512), light=(0.45, -1.0, 0.25), tf_path=None,
           **params):
    zyx, spacing, origin, directions = load_nifti(path)
    lo, hi = np.percentile(zyx, [1, 99.9])
    with umbra.Context() as ctx:
        if tf_path:
            # a ParaView preset (or umbra's text format); a preset spans data values, e.g. HU
            vol = umbra.Volume(ctx, zyx, spacing=spacing, origin=origin, directions=directions)
            tf = ctx.load_transfer_function(tf_path)
        else:
            vol = umbra.Volume(ctx, zyx, spacing=spacing, origin=origin, directions=directions,
                               value_range=(float(lo), float(hi)))
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
        ctx.write_image(out, img)
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
