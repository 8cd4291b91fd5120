#!/usr/bin/env python3
# SPDX-License-Identifier: Apache-2.0
"""bench/vtk_raycast.py: VTK's CPU ray caster on the view `umbra-bench raycast` times.

umbra-bench runs this script with the volume, camera, transfer function and sample distance it
gives umbra, with --serve: after set-up and the warm-up frames it prints "ready", then renders one
frame for each line "frame" (unshaded) or "frame shaded" it reads on stdin and answers
"ms <milliseconds>", so umbra-bench can interleave VTK's frames with its own and a change in the
machine's load touches all alike. Run by
hand (without --serve) it renders --runs frames and prints one line:

    vtk_fixedpoint <ms_median> <ms_min> <ms_max>

Timed is vtkRenderWindow.Render() of an off-screen window holding one vtkVolume drawn by
vtkFixedPointVolumeRayCastMapper (all CPU threads, linear interpolation; no shading, or with
--shading KD KS N and a "frame shaded" request its gradient shading: ambient 0, diffuse KD,
specular KS, specular power N, one directional white light shining along --light, as umbra's),
after warm-up renders (of both kinds when --shading is given, so that the mapper's encoded
normals, which it computes once per volume, are ready): the frame time a VTK user sees. The mapper's own ray-casting time
(GetTimeToDraw) is reported on stderr. The view matches umbra's: the volume's voxel centres are
placed where umbra puts them (box centred on the origin), the camera is the same look-at
perspective camera, the sample distance is the same world step with automatic adjustment off and
one ray per pixel, and the opacity is per unit distance of one voxel (VTK's scalar opacity unit
distance = the smallest spacing), as umbra's alpha is per voxel step.
"""
import argparse
import statistics
import sys
import time

import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (registers the OpenGL render window)
import vtkmodules.vtkRenderingVolumeOpenGL2  # noqa: F401  (the mapper's image display helper)
from vtkmodules.vtkCommonDataModel import vtkPiecewiseFunction
from vtkmodules.vtkImagingCore import vtkImageChangeInformation
from vtkmodules.vtkIOImage import vtkNrrdReader, vtkPNGWriter
from vtkmodules.vtkRenderingCore import (vtkColorTransferFunction, vtkLight, vtkRenderer,
                                         vtkRenderWindow, vtkVolume, vtkVolumeProperty,
                                         vtkWindowToImageFilter)
from vtkmodules.vtkRenderingVolume import vtkFixedPointVolumeRayCastMapper


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nrrd", required=True, help="volume (.nhdr/.nrrd)")
    ap.add_argument("--size", nargs=2, type=int, default=[512, 512])
    ap.add_argument("--eye", nargs=3, type=float, required=True)
    ap.add_argument("--target", nargs=3, type=float, default=[0.0, 0.0, 0.0])
    ap.add_argument("--up", nargs=3, type=float, default=[0.0, 1.0, 0.0])
    ap.add_argument("--fovy", type=float, default=30.0, help="vertical field of view, degrees")
    ap.add_argument("--step", type=float, required=True, help="sample distance, world units")
    ap.add_argument("--range", nargs=2, type=float, required=True,
                    help="data values mapped to 0 and 1 of the transfer function")
    ap.add_argument("--tf", required=True,
                    help="control points 'v,r,g,b,a;...' over the normalised range, alpha per voxel")
    ap.add_argument("--runs", type=int, default=7)
    ap.add_argument("--warmup", type=int, default=2)
    ap.add_argument("--save", help="write the last frame to this PNG")
    ap.add_argument("--shading", nargs=3, type=float, metavar=("KD", "KS", "N"),
                    help="Blinn-Phong coefficients for 'frame shaded' requests (and --shade)")
    ap.add_argument("--light", nargs=3, type=float, default=[0.0, -1.0, 0.0],
                    help="direction the directional light shines along")
    ap.add_argument("--shade", action="store_true", help="without --serve: render shaded")
    ap.add_argument("--serve", action="store_true",
                    help="render a frame per 'frame' line on stdin (see above)")
    a = ap.parse_args()

    reader = vtkNrrdReader()
    reader.SetFileName(a.nrrd)
    reader.Update()
    image = reader.GetOutput()
    dims = image.GetDimensions()
    spacing = image.GetSpacing()
    if min(dims) < 1:
        sys.exit("vtk_raycast.py: could not read %s" % a.nrrd)
    # umbra: the box [-extent/2, extent/2], voxel i's centre at -extent/2 + (i + 0.5) spacing.
    origin = [-0.5 * dims[k] * spacing[k] + 0.5 * spacing[k] for k in range(3)]
    place = vtkImageChangeInformation()
    place.SetInputConnection(reader.GetOutputPort())
    place.SetOutputOrigin(origin)

    lo, hi = a.range
    colour = vtkColorTransferFunction()
    opacity = vtkPiecewiseFunction()
    for point in a.tf.split(";"):
        v, r, g, b, alpha = (float(x) for x in point.split(","))
        value = lo + v * (hi - lo)
        colour.AddRGBPoint(value, r, g, b)
        opacity.AddPoint(value, alpha)

    prop = vtkVolumeProperty()
    prop.SetColor(colour)
    prop.SetScalarOpacity(opacity)
    prop.SetScalarOpacityUnitDistance(min(spacing))
    prop.SetInterpolationTypeToLinear()
    prop.ShadeOff()
    if a.shading:
        kd, ks, power = a.shading
        prop.SetAmbient(0.0)
        prop.SetDiffuse(kd)
        prop.SetSpecular(ks)
        prop.SetSpecularPower(power)

    mapper = vtkFixedPointVolumeRayCastMapper()
    mapper.SetInputConnection(place.GetOutputPort())
    mapper.AutoAdjustSampleDistancesOff()
    mapper.LockSampleDistanceToInputSpacingOff()
    mapper.SetSampleDistance(a.step)
    mapper.SetInteractiveSampleDistance(a.step)
    mapper.SetImageSampleDistance(1.0)

    volume = vtkVolume()
    volume.SetMapper(mapper)
    volume.SetProperty(prop)

    ren = vtkRenderer()
    ren.SetBackground(0.0, 0.0, 0.0)
    ren.AddVolume(volume)
    # umbra's directional light instead of VTK's default headlight (the cost is the same: the
    # mapper shades through tables over its encoded normals, rebuilt per frame for any light).
    ren.AutomaticLightCreationOff()
    light = vtkLight()
    light.SetLightTypeToSceneLight()
    light.SetPositional(False)
    light.SetPosition(*[-x for x in a.light])
    light.SetFocalPoint(0.0, 0.0, 0.0)
    light.SetColor(1.0, 1.0, 1.0)
    ren.AddLight(light)
    cam = ren.GetActiveCamera()
    cam.SetPosition(*a.eye)
    cam.SetFocalPoint(*a.target)
    cam.SetViewUp(*a.up)
    cam.SetViewAngle(a.fovy)
    ren.ResetCameraClippingRange()

    win = vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.SetSize(a.size[0], a.size[1])
    win.AddRenderer(ren)

    def frame(shaded=False):
        if shaded:
            prop.ShadeOn()
        else:
            prop.ShadeOff()
        cam.Modified()  # nothing may be cached between frames
        t0 = time.perf_counter()
        win.Render()
        return (time.perf_counter() - t0) * 1e3

    for _ in range(a.warmup):
        frame(a.shade)
        if a.serve and a.shading:
            frame(True)
    wall, cast = [], []
    if a.serve:
        print("ready", flush=True)
        while True:
            request = sys.stdin.readline().strip()
            if request not in ("frame", "frame shaded"):
                break
            wall.append(frame(request == "frame shaded"))
            cast.append(mapper.GetTimeToDraw() * 1e3)
            print("ms %.3f" % wall[-1], flush=True)
    else:
        for _ in range(a.runs):
            wall.append(frame(a.shade))
            cast.append(mapper.GetTimeToDraw() * 1e3)

    if a.save:
        grab = vtkWindowToImageFilter()
        grab.SetInput(win)
        grab.Update()
        png = vtkPNGWriter()
        png.SetFileName(a.save)
        png.SetInputConnection(grab.GetOutputPort())
        png.Write()

    if cast:
        print("vtk_fixedpoint: %d threads, ray casting alone (GetTimeToDraw) median %.1f ms"
              % (mapper.GetNumberOfThreads(), statistics.median(cast)), file=sys.stderr)
    if not a.serve:
        print("vtk_fixedpoint %.3f %.3f %.3f" % (statistics.median(wall), min(wall), max(wall)))


if __name__ == "__main__":
    main()
