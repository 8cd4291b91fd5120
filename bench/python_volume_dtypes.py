#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""bench/python_volume_dtypes.py: what umbra.Volume's dtype conversion costs.

Times umbra.Volume(ctx, array) (the array to the device, value range given so that only the
conversion and the upload differ) for an array umbra stores as it is and for the same values in
a dtype it converts, N^3 voxels, in interleaved rounds so that a change in the machine's load
touches every case alike, after one warm-up each. Prints one line per case:

    <case> <median ms> <ratio to the same values in the stored type>

    python bench/python_volume_dtypes.py [--size 256] [--runs 7]     # with umbra installed
"""
import argparse
import statistics
import time

import numpy as np

import umbra


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--runs", type=int, default=7)
    a = ap.parse_args()
    n = a.size
    unit = np.random.default_rng(0).random((n, n, n), dtype=np.float32)
    u16 = np.round(unit * 4000).astype(np.uint16)
    i16 = (u16.astype(np.int16) - 1024)
    f32 = np.round(unit * 100000).astype(np.float32)
    # (name, array, the same values in the type umbra stores them in)
    cases = [
        ("float64 -> float32", f32.astype(np.float64), f32),
        ("float16 -> float32", unit.astype(np.float16), unit.astype(np.float16).astype(np.float32)),
        ("int32 -> uint16", u16.astype(np.int32), u16),
        ("int64 -> int16", i16.astype(np.int64), i16),
        ("int32 -> float32", f32.astype(np.int32), f32),
        ("bool -> uint8", unit > 0.5, (unit > 0.5).astype(np.uint8)),
    ]
    with umbra.Context() as ctx:
        def once(arr):
            t = time.perf_counter()
            umbra.Volume(ctx, arr, value_range=(0, 1)).close()
            return (time.perf_counter() - t) * 1e3

        arrays = [arr for _, given, stored in cases for arr in (given, stored)]
        times = {id(arr): [] for arr in arrays}
        for arr in arrays:
            once(arr)
        for _ in range(a.runs):
            for arr in arrays:
                times[id(arr)].append(once(arr))
        print(f"# {n}^3 voxels on {ctx.device_name}, medians of {a.runs}")
        for name, given, stored in cases:
            g, s = statistics.median(times[id(given)]), statistics.median(times[id(stored)])
            print(f"{name:20s} {g:8.1f} ms  {g / s:5.2f}x the {stored.dtype} array's {s:.1f} ms")


if __name__ == "__main__":
    main()
