#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""tests/viewer/compare.py A.png B.png [--skip X,Y,W,H] [--tolerance T]: the largest difference
of two 8-bit sRGB images' RGB channels, in 1/255 steps, outside an optional rectangle (the
viewer's panel); exits 1 when the sizes differ or the difference is above T (default 2), or when
fewer than 1000 pixels are compared."""
import argparse
import sys

import numpy as np
from PIL import Image


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("a")
    ap.add_argument("b")
    ap.add_argument("--skip", help="X,Y,W,H: a rectangle left out (pixels, from the top left)")
    ap.add_argument("--tolerance", type=int, default=2)
    o = ap.parse_args()
    a = np.asarray(Image.open(o.a).convert("RGB")).astype(np.int32)
    b = np.asarray(Image.open(o.b).convert("RGB")).astype(np.int32)
    if a.shape != b.shape:
        print(f"compare: sizes differ: {o.a} {a.shape[1]}x{a.shape[0]}, "
              f"{o.b} {b.shape[1]}x{b.shape[0]}")
        return 1
    keep = np.ones(a.shape[:2], dtype=bool)
    if o.skip:
        x, y, w, h = (int(v) for v in o.skip.split(","))
        keep[max(y, 0):max(y + h, 0), max(x, 0):max(x + w, 0)] = False
    diff = np.abs(a - b).max(axis=2)[keep]
    worst = int(diff.max()) if diff.size else 0
    print(f"compare: {o.a} vs {o.b}: {diff.size} pixels compared, max difference "
          f"{worst}/255, {int((diff > 0).sum())} pixels differ (tolerance {o.tolerance}/255)")
    if diff.size < 1000:
        print("compare: too few pixels compared")
        return 1
    return 0 if worst <= o.tolerance else 1


if __name__ == "__main__":
    sys.exit(main())
