# SPDX-License-Identifier: Apache-2.0
"""Progress and cancellation from Python: the fractions a render reports, a callable that cancels
(umbra.Error with status ERROR_CANCELLED, the renderer usable afterwards), an exception in the
callable (or in truth-testing what it returned) and Ctrl-C (SIGINT) cancelling a render and
propagating, bad callables refused, and another thread that reaches a renderer while its callable
runs told so."""

import ctypes
import functools
import os
import signal
import threading

import numpy as np
import pytest

import umbra

W, H = 64, 48


@pytest.fixture
def renderer(ctx):
    scene = umbra.Scene(ctx, "spheres")
    with scene.renderer() as r:
        r.set_shadow(technique="cssm", map_size=128)
        yield r


def test_fractions_are_monotone_and_end_at_1(renderer):
    seen = []
    renderer.progress = seen.append          # returns None: never cancels
    assert renderer.progress == seen.append
    for technique in ("cssm", "convolution", "none"):
        if technique == "convolution":        # light from the viewer's side, as it needs
            cam = renderer.camera
            renderer.light = umbra.Light.directional(tuple(np.subtract(cam.target, cam.eye)))
        seen.clear()
        renderer.render(W, H, technique=technique)
        # cssm reports its shadow build and its render; the others may be one piece at this size
        assert len(seen) >= (2 if technique == "cssm" else 1), (technique, seen)
        assert all(0 <= f <= 1 for f in seen), seen
        assert all(a <= b for a, b in zip(seen, seen[1:])), seen
        assert seen[-1] == 1.0
    seen.clear()
    renderer.query_shadow(np.zeros((4, 3), np.float32))
    assert seen and seen[-1] == 1.0


def test_cancel_raises_cancelled_and_renderer_renders_again(renderer):
    calls = []

    def cancel(f):
        calls.append(f)
        return True

    renderer.progress = cancel
    renderer.light = umbra.Light.directional((1, -1, 0))   # a shadow map to rebuild
    out = np.full((H, W, 4), -1, np.float32)
    with pytest.raises(umbra.Error, match="cancelled by the progress callback") as e:
        renderer.render(W, H, out=out)
    assert e.value.status == umbra.Status.ERROR_CANCELLED
    assert len(calls) == 1                    # nothing after the cancelling call
    assert (out == -1).all()                  # cancelled in the shadow build, before any pixel
    renderer.progress = None
    again = renderer.render(W, H)
    assert np.isfinite(again).all() and np.ptp(again[..., :3]) > 0.2
    # and the context keeps no sticky error: a shadow query works too
    assert renderer.query_shadow(np.zeros((1, 3), np.float32)).shape == (1, 3)


def test_cancel_mid_render_then_same_pixels(ctx):
    scene = umbra.Scene(ctx, "spheres")
    with scene.renderer() as r:
        r.set_shadow(technique="cssm", map_size=128)
        clean = r.render(W, H)
        r.light = umbra.Light.directional((0.3, -1, 0.2))
        r.progress = lambda f: f > 0          # lets the first piece run, then cancels
        with pytest.raises(umbra.Error) as e:
            r.render(W, H)
        assert e.value.status == umbra.Status.ERROR_CANCELLED
        r.progress = None
        r.light = scene.light                  # back to the first light: the same picture
        assert np.array_equal(r.render(W, H), clean)


def test_exception_in_the_callable_cancels_and_propagates(renderer):
    def boom(f):
        raise ValueError("stop here")

    renderer.progress = boom
    with pytest.raises(ValueError, match="stop here"):
        renderer.render(W, H)
    renderer.progress = None
    assert np.isfinite(renderer.render(W, H)).all()


def test_a_result_that_fails_truth_testing_propagates(renderer):
    # the callable returns; judging its result raises (numpy arrays of several elements do too)
    class Undecided:
        def __bool__(self):
            raise ValueError("no truth value here")

    renderer.progress = lambda f: Undecided()
    with pytest.raises(ValueError, match="no truth value here"):
        renderer.render(W, H)
    renderer.progress = lambda f: np.array([True, False])
    with pytest.raises(ValueError, match="truth value of an array"):
        renderer.render(W, H)
    renderer.progress = None
    assert np.isfinite(renderer.render(W, H)).all()


def test_another_thread_is_told_the_renderer_is_busy(renderer):
    # while the callable waits (releasing the GIL), a second thread calls the same renderer: it
    # is refused as a second thread, not as the callable, and the first render completes
    started, tried = threading.Event(), threading.Event()
    errors = []

    def hold(f):
        if not started.is_set():
            started.set()
            assert tried.wait(60)

    def other():
        assert started.wait(60)
        try:
            renderer.render(8, 8)
        except RuntimeError as e:
            errors.append(str(e))
        finally:
            tried.set()

    renderer.progress = hold
    renderer.light = umbra.Light.directional((0.4, -1, 0.3))
    t = threading.Thread(target=other)
    t.start()
    image = renderer.render(W, H)
    t.join(60)
    assert len(errors) == 1, errors
    assert "another thread renders with it" in errors[0], errors
    assert "own progress callback" not in errors[0]
    renderer.progress = None
    assert np.array_equal(image, renderer.render(W, H))


def test_exception_from_ctrl_c_in_the_callable(renderer):
    # Ctrl-C while the callable's Python code runs: KeyboardInterrupt raised inside it
    def interrupt(f):
        os.kill(os.getpid(), signal.SIGINT)

    renderer.progress = interrupt
    renderer.light = umbra.Light.directional((0.2, -1, 0.4))
    out = np.full((H, W, 4), -1, np.float32)
    with pytest.raises(KeyboardInterrupt):
        renderer.render(W, H, out=out)
    assert (out == -1).all()
    renderer.progress = None
    assert np.isfinite(renderer.render(W, H)).all()


@pytest.mark.parametrize("with_callable", [False, True])
def test_ctrl_c_during_device_work_cancels_the_render(renderer, with_callable):
    # Ctrl-C that arrives while C code runs (no Python bytecode to notice it): the C progress
    # callback's signal check must cancel the render. The signal is sent from C (libc's kill
    # through ctypes, which runs no bytecode) at the first report, in the shadow build; a render
    # that missed it would go on and write every pixel before Python raised KeyboardInterrupt.
    libc = ctypes.CDLL(None, use_errno=True)
    # kill(pid, sig) called as f(fraction): the prototype takes the fraction as a third argument,
    # which kill ignores (extra arguments are harmless in the C calling conventions)
    proto = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_int, ctypes.c_int, ctypes.c_float)
    kill = functools.partial(proto(("kill", libc)), os.getpid(), signal.SIGINT)
    seen = []
    renderer.progress = kill
    renderer.light = umbra.Light.directional((0.5, -1, 0.1))
    out = np.full((H, W, 4), -1, np.float32)
    with pytest.raises(KeyboardInterrupt):
        renderer.render(W, H, out=out)
    assert (out == -1).all()
    if with_callable:
        # the same with a Python callable installed that itself sees no signal
        renderer.progress = lambda f: seen.append(f)
        renderer.light = umbra.Light.directional((0.5, -1, 0.2))
        assert np.isfinite(renderer.render(W, H)).all() and seen[-1] == 1.0
    renderer.progress = None
    renderer.light = umbra.Light.directional((0.5, -1, 0.3))
    assert np.isfinite(renderer.render(W, H)).all()


@pytest.mark.parametrize("use", ["render", "close", "stats", "set_shadow"])
def test_the_callable_cannot_use_its_renderer(renderer, use):
    def reenter(f):
        if use == "render":
            renderer.render(8, 8)
        elif use == "close":
            renderer.close()
        elif use == "stats":
            renderer.stats
        else:
            renderer.set_shadow(technique="none")

    renderer.progress = reenter
    with pytest.raises(RuntimeError, match="own progress callback"):
        renderer.render(W, H)
    renderer.progress = None
    assert not renderer.closed
    assert renderer.shadow.technique == umbra.Technique.CSSM
    assert np.isfinite(renderer.render(W, H)).all()


def test_a_callable_may_remove_itself(renderer):
    seen = []

    def once(f):
        seen.append(f)
        renderer.progress = None

    renderer.progress = once
    renderer.render(W, H)
    assert len(seen) == 1 and renderer.progress is None


def test_progress_must_be_callable(renderer):
    with pytest.raises(TypeError, match="int is not callable"):
        renderer.progress = 3


def test_a_callable_that_refers_to_its_renderer_is_collected(ctx):
    # renderer -> callable -> renderer: a cycle the garbage collector must see through
    import gc

    collected = []

    class Watcher:
        def __init__(self, renderer):
            self.renderer = renderer

        def __call__(self, f):
            return None

        def __del__(self):
            collected.append(True)

    r = umbra.Scene(ctx, "spheres").renderer()
    r.progress = Watcher(r)
    r.render(16, 16)
    del r
    gc.collect()
    assert collected
