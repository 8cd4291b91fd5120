# SPDX-License-Identifier: Apache-2.0
"""umbra and Python's multiprocessing. OpenCL does not survive fork(): a child made with the
"fork" start method (Linux's default before Python 3.14) gets umbra.Error with status
ERROR_UNSUPPORTED and a message naming "spawn" from every call that would use OpenCL, at once,
instead of hanging in it; a child made with "spawn" creates its own context and renders."""

import multiprocessing
import queue as queue_module
import warnings

import numpy as np
import pytest

import umbra


def _use_inherited(results, renderer):
    """In a forked child: the parent's renderer, a new context, a new volume."""
    out = []
    for name, call in (
        ("render", lambda: renderer.render(8, 8)),
        ("query_shadow", lambda: renderer.query_shadow(np.zeros((1, 3), np.float32))),
        ("Context", lambda: umbra.Context()),
    ):
        try:
            call()
            out.append((name, None, ""))
        except umbra.Error as e:
            out.append((name, e.status, str(e)))
    results.put(out)


def _render_spheres(results):
    """In a spawned child: its own context and a small render."""
    with umbra.Context() as ctx:
        with umbra.Scene(ctx, "spheres").renderer() as r:
            image = r.render(16, 16)
    results.put(float(image[..., 3].max()))


def _run(method, target, *args):
    mp = multiprocessing.get_context(method)
    results = mp.Queue()
    with warnings.catch_warnings():
        # Python 3.12+ warns that forking a multi-threaded process (OpenCL's threads) is unsafe:
        # that is what this test is about
        warnings.simplefilter("ignore", DeprecationWarning)
        p = mp.Process(target=target, args=(results, *args))
        p.start()
    try:
        got = results.get(timeout=120)
    except queue_module.Empty:
        got = None
    p.join(60)
    if p.is_alive():
        p.kill()
        p.join()
    return got, p.exitcode


def test_forked_child_gets_a_clear_error(ctx):
    with umbra.Scene(ctx, "spheres").renderer() as r:
        before = r.render(16, 16)
        got, code = _run("fork", _use_inherited, r)
        assert got is not None, "the forked child gave no answer: it hung"
        assert code == 0
        for name, status, message in got:
            assert status == umbra.Status.ERROR_UNSUPPORTED, (name, status, message)
            assert "forked" in message and "'spawn'" in message, (name, message)
        # the parent is unharmed
        assert np.array_equal(r.render(16, 16), before)


def test_spawned_child_renders():
    got, code = _run("spawn", _render_spheres)
    assert code == 0
    assert got is not None and got > 0.5
