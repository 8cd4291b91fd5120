# SPDX-License-Identifier: Apache-2.0
"""Pictures for a Jupyter notebook: umbra renders to a NumPy array; umbra.to_srgb8() makes it
displayable (matplotlib's imshow, PIL.Image.fromarray) and show() returns a PIL image, which
Jupyter draws inline as the cell's value.

    from notebook import render_scene, show
    img = render_scene("spheres", technique="reference")   # (240, 320, 4) float32
    show(img)                                              # in a notebook: the picture

Run as a script it writes one PNG per technique into the given folder (default: the current one).
"""

import contextlib
import pathlib
import sys

import numpy as np

import umbra
from umbra import to_srgb8


def render_scene(name="spheres", technique="reference", width=320, height=240, ctx=None,
                 **params):
    """A built-in scene as premultiplied linear RGBA, (height, width, 4) float32, over an opaque
    dark background. Pass a Context to reuse one (the first one on PoCL takes seconds)."""
    with umbra.Context() if ctx is None else contextlib.nullcontext(ctx) as c:
        scene = umbra.Scene(c, name)
        with scene.renderer() as r:
            if technique == "convolution":
                # convolution shadows need the light on the viewer's side
                eye, target = np.array(scene.camera.eye), np.array(scene.camera.target)
                r.light = umbra.Light.directional(tuple(target - eye + (0, -0.3 * np.linalg.norm(eye), 0)))
            r.set_options(scene.options, background=(0.08, 0.08, 0.1, 1.0))
            return r.render(width, height, technique=technique, **params)


def show(rgba):
    """A PIL image of the render (Jupyter displays it inline)."""
    from PIL import Image
    return Image.fromarray(to_srgb8(rgba), "RGBA")


if __name__ == "__main__":
    out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
    out.mkdir(parents=True, exist_ok=True)
    for t in umbra.technique_names():
        show(render_scene(technique=t, map_size=512)).save(out / f"spheres_{t}.png")
        print(f"wrote {out / f'spheres_{t}.png'}", file=sys.stderr)
