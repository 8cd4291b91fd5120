#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""bench/cancel_latency.py: how soon Ctrl-C stops a long render, from the command line and from
Python (issue #28 item 5; `umbra-bench progress` measures the C API itself).

Each run starts a reference render of the built-in spheres (the CLI's default scene) at the given
shadow step and size, in a child process: `umbra-render`, or a Python interpreter that imports
umbra and calls Renderer.render. Once the child says it has begun rendering (the CLI's first
progress line on stderr; Python prints a line before the call), SIGINT is sent after the given
delay, and the time from the signal to the child's report of the interrupt is taken (umbra-render
exits; the Python child catches KeyboardInterrupt and prints time.monotonic(), the same clock as
this script's on Linux). Prints one CSV row per run.

usage: cancel_latency.py [--cli PATH] [--python PATH] [--step S] [--size N] [--after T,T,...]
  --cli     umbra-render to measure (default build/umbra-render; "" skips it)
  --python  an interpreter that imports umbra (default build/python-venv/bin/python; "" skips)
"""

import argparse
import os
import signal
import subprocess
import sys
import time

CHILD = r"""
import sys, time, umbra
step, size = float(sys.argv[1]), int(sys.argv[2])
with umbra.Context() as ctx:
    r = umbra.Scene(ctx, "spheres").renderer()
    r.set_shadow(technique="reference", reference_step=step)
    r.render(8, 8)                       # compiles the kernel before the timed call
    print("rendering", flush=True)
    try:
        r.render(size, size)
        print("finished", time.monotonic(), flush=True)
    except KeyboardInterrupt:
        print("interrupted", time.monotonic(), flush=True)
"""


def run_cli(cli, step, size, after):
    p = subprocess.Popen([cli, "--technique", "reference", "--reference-step", str(step),
                          "--size", f"{size}x{size}", "--progress", "--out", os.devnull + ".png"],
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    # the first progress report ("rendering:") says the frame has begun
    buf = b""
    while b"rendering" not in buf:
        c = p.stderr.read(1)
        if not c:
            break
        buf += c
    time.sleep(after)
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    p.stderr.read()
    p.wait()
    return time.monotonic() - sent, p.returncode


def run_python(python, step, size, after):
    p = subprocess.Popen([python, "-c", CHILD, str(step), str(size)], stdout=subprocess.PIPE,
                         text=True)
    assert p.stdout.readline().strip() == "rendering"
    time.sleep(after)
    sent = time.monotonic()
    p.send_signal(signal.SIGINT)
    words = p.stdout.readline().split()
    p.wait()
    if len(words) == 2 and words[0] == "interrupted":
        return float(words[1]) - sent, p.returncode
    return float("nan"), p.returncode


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    build = os.path.join(here, "..", "build")
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cli", default=os.path.join(build, "umbra-render"))
    ap.add_argument("--python", default=os.path.join(build, "python-venv", "bin", "python"))
    ap.add_argument("--step", type=float, default=0.05)
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--after", default="1,3,7")
    a = ap.parse_args()
    print("who,step,size,after_s,latency_s,exit")
    for after in (float(x) for x in a.after.split(",")):
        for who, path, run in (("cli", a.cli, run_cli), ("python", a.python, run_python)):
            if path:
                latency, code = run(path, a.step, a.size, after)
                print(f"{who},{a.step},{a.size},{after},{latency:.3f},{code}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
