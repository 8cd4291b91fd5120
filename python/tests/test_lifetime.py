# SPDX-License-Identifier: Apache-2.0
"""Objects close deterministically, survive being collected in any order, and do not leak over a
thousand create/release cycles."""

import gc
import os
import subprocess
import sys
import textwrap

import numpy as np

import umbra

TF = np.array([[1, 1, 1, 0], [1, 0.5, 0.2, 0.3]], np.float32)


def test_objects_outlive_what_made_them():
    ctx = umbra.Context()
    vol = umbra.Volume(ctx, np.random.default_rng(0).random((8, 8, 8), dtype=np.float32))
    tf = umbra.TransferFunction(ctx, TF)
    r = umbra.Renderer(ctx, vol, tf)
    table = tf.table
    # close (or drop) the context, volume and transfer function first: the renderer holds them
    ctx.close()
    vol.close()
    tf.close()
    del ctx, vol, tf
    gc.collect()
    img = r.render(16, 16, technique="reference")
    assert img[..., 3].max() > 0
    assert table[1, 3] == np.float32(0.3)   # the table view keeps its table
    r.close()


def test_collection_in_any_order():
    for order in ([0, 1, 2, 3], [3, 2, 1, 0], [1, 3, 0, 2], [2, 0, 3, 1]):
        ctx = umbra.Context()
        objs = [ctx, umbra.Volume(ctx, np.arange(27, dtype=np.uint8).reshape(3, 3, 3)),
                umbra.TransferFunction(ctx, TF)]
        objs.append(umbra.Renderer(ctx, objs[1], objs[2]))
        objs[3].render(4, 4)
        for i in order:
            objs[i] = None
            gc.collect()


def test_context_manager_closes():
    with umbra.Context() as ctx:
        with umbra.Volume(ctx, np.arange(8, dtype=np.uint8).reshape(2, 2, 2)) as v:
            pass
        assert v.closed
    assert ctx.closed


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def cycle(ctx, data):
    with umbra.Volume(ctx, data) as vol, umbra.TransferFunction(ctx, TF) as tf, \
            umbra.Renderer(ctx, vol, tf) as r:
        r.render(8, 8)
    # and the same without closing: left to the garbage collector
    r = umbra.Renderer(ctx, umbra.Volume(ctx, data), umbra.TransferFunction(ctx, TF))
    r.query_shadow(np.zeros((4, 3), np.float32))
    # a constructor that fails half-way (bad options after the volume was set) frees what it made
    try:
        umbra.Renderer(ctx, umbra.Volume(ctx, data), umbra.TransferFunction(ctx, TF),
                       options=umbra.RenderOptions(step=-1))
    except umbra.Error as e:
        assert "step" in e.message
    else:
        raise AssertionError("a negative step was accepted")


def test_no_leak_over_a_thousand_cycles(ctx):
    # 128 KiB of voxels a cycle: a volume leaked per cycle would grow the RSS by 125 MiB
    data = np.random.default_rng(0).random((32, 32, 32), dtype=np.float32)
    for _ in range(50):
        cycle(ctx, data)
    gc.collect()
    before = rss_bytes()
    for _ in range(1000):
        cycle(ctx, data)
    gc.collect()
    growth = rss_bytes() - before
    print(f"RSS growth over 1000 cycles: {growth / 2**20:.2f} MiB")
    assert growth < 16 * 2**20, growth


def test_nanobind_reports_no_leaked_instances(tmp_path):
    # nanobind prints "leaked" at exit for any wrapper still alive then
    code = textwrap.dedent("""
        import numpy as np, umbra
        ctx = umbra.Context()
        s = umbra.Scene(ctx, "slab", 16)
        r = s.renderer()
        r.render(8, 8, technique="cssm", map_size=64)
        t = s.tf.table
        img = ctx.read_image  # a bound method
    """)
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert "leak" not in p.stderr, p.stderr
