#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# tests/viewer/viewer.sh CASE UMBRA_VIEW UMBRA_RENDER SOURCE_DIR: umbra-view in a window on a
# virtual X server (xvfb-run: Xvfb with Mesa's software OpenGL, llvmpipe), against umbra-render.
# Each case takes the window's pixels with --snapshot and compares them with umbra-render's PNG
# of the same view: 8-bit sRGB, at most 2/255 apart in any channel (tests/viewer/compare.py).
#   spheres      the built-in spheres scene, reference shadows, --no-gui
#   volume       a walnut-like CT volume made by tests/viewer/make_nut.py (the walnut itself is in
#                ../shared/data, which CI does not have), loaded from a NRRD file with
#                examples/walnut.tf, the walnut example's camera and point light, deep shadow map,
#                shading, --no-gui
#   clip         the spheres clipped (a plane and a crop box, threshold shadows) and in MIP: the
#                view the viewer prints carries --clip-plane, --crop and --mode, and umbra-render
#                given it draws the viewer's frame (outside the panel)
#   options      the command line, without a window: the viewer's own options refused with
#                exit 1 and a message naming the value, umbra-render's options and files
#                checked by umbra-render's parser (one getopt_long table: prefixes, --opt=value,
#                a prefix of a viewer option and an umbra-render one refused as ambiguous), every
#                message naming umbra-view, no display is exit 2
#   light_orbit  the spheres with CSSM (7 taps, a 128^2 map) and the panel shown: --frames 6
#                --orbit light replays a full turn of the light; every frame must print its times
#                and have rebuilt the map as CSSM's draft (the light moved; interaction auto,
#                the viewer's default), then the last frame (the full map), outside the
#                panel, must match umbra-render given the view the viewer prints (its light as it
#                ended, the technique's parameters by their registry keys)
set -euo pipefail
case=${1:?usage: viewer.sh CASE UMBRA_VIEW UMBRA_RENDER SOURCE_DIR}
view=$(realpath "$2")
render=$(realpath "$3")
src=$(realpath "$4")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp"
python=/usr/bin/python3 # Debian's, with python3-numpy and python3-pil
fail() { echo "viewer.sh $case: FAIL: $*" >&2; exit 1; }

# Under AddressSanitizer (.ci/sanitize.sh) umbra-view runs without LeakSanitizer (ASan and UBSan
# still check it; umbra-render keeps the leak check): in some runs (1 in 5 to 10) Mesa's llvmpipe
# driver loses 240 bytes allocated during the GUI's draw calls (valgrind shows the calls come from
# ImGui_ImplOpenGL3_RenderDrawData into swrast_dri.so), and the driver, built without frame
# pointers and unloaded by glfwTerminate, leaves LeakSanitizer a one-frame stack in an unknown
# module, which no suppression can name.
noleak=()
if ldd "$view" 2>/dev/null | grep -q libasan; then
    noleak=(env "ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0")
fi

# Runs umbra-view in a fresh virtual X server; its stdout goes to view.out.
run_view() {
    xvfb-run -a -s "-screen 0 1280x1024x24" "${noleak[@]}" timeout 300 "$view" "$@" \
        >view.out 2>view.err || { cat view.out view.err; fail "umbra-view $* exited with $?"; }
    cat view.out view.err
}

case $case in
spheres)
    args=(--scene spheres --technique reference --size 256x192)
    run_view "${args[@]}" --no-gui --snapshot view.png
    "$render" "${args[@]}" --out render.png
    "$python" "$src/tests/viewer/compare.py" view.png render.png || fail "the images differ"
    ;;
volume)
    "$python" "$src/tests/viewer/make_nut.py" nut.nhdr
    # examples/walnut_scene.h's view for this box (diagonal 196.6): eye (0.45, 0.6, 1.55) d,
    # target (0.1 d, -0.3 y extent, 0), point light (-1, 1.9, -0.35) d.
    args=(--volume nut.nhdr --tf "$src/examples/walnut.tf" --technique deep --shading --colored
          --eye 88.47,117.96,304.73 --target 19.66,-28.8,0 --fov 34
          --light-pos -196.6,373.54,-68.81 --size 320x240)
    run_view "${args[@]}" --no-gui --snapshot view.png
    "$render" "${args[@]}" --out render.png
    "$python" "$src/tests/viewer/compare.py" view.png render.png || fail "the images differ"
    ;;
light_orbit)
    frames=6
    run_view --scene spheres --technique cssm --taps 7 --map-size 128 --size 512x288 \
        --frames $frames --orbit light --snapshot view.png
    n=$(grep -c '^frame [0-9]*/'$frames': ' view.out || true)
    [ "$n" -eq $frames ] || fail "$n frame lines, expected $frames"
    # Every frame rebuilt the map: the light moved each frame.
    n=$(grep -c '^frame .*shadow build [0-9.]* ms rebuilt' view.out || true)
    [ "$n" -eq $frames ] || fail "$n of $frames frames rebuilt the map"
    # The viewer's default is interaction auto: each moving-light frame is CSSM's draft, and the
    # snapshot (compared below with a fresh umbra-render) is the full map that follows.
    n=$(grep -c '^frame .*shadow build [0-9.]* ms rebuilt, draft' view.out || true)
    [ "$n" -eq $frames ] || fail "$n of $frames frames used the draft"
    grep -q "^median of $frames frames (light orbit" view.out || fail "no median line"
    viewargs=$(sed -n 's/^view: //p' view.out)
    [ -n "$viewargs" ] || fail "the viewer printed no view"
    for want in "--technique cssm" "--taps 7" "--map-size 128" "--ray-block 0"; do
        grep -qe " $want" <<<" $viewargs" || fail "the view lacks $want: $viewargs"
    done
    panel=$(sed -n 's/.*panel at \([0-9]*\),\([0-9]*\) size \([0-9]*\)x\([0-9]*\).*/\1,\2,\3,\4/p' \
            view.err)
    [ -n "$panel" ] || fail "the snapshot names no panel rectangle"
    # shellcheck disable=SC2086 # the view is a list of options
    "$render" --scene spheres $viewargs --out render.png
    "$python" "$src/tests/viewer/compare.py" view.png render.png --skip "$panel" ||
        fail "the images differ outside the panel"
    ;;
clip)
    # The clip region and the projection mode as the panel keeps them: the view the viewer prints
    # carries them (--clip-plane, --crop, --mode), and umbra-render given that view draws the
    # viewer's frame. Threshold-map shadows with a plane and a crop box; then MIP with a crop box.
    for extra in "--technique threshold --clip-plane 1,0,0.25,0.125 --crop 2,0,4,60,50,58" \
                 "--technique none --mode mip --crop 0,8,0,63,63,50"; do
        # shellcheck disable=SC2086 # a list of options
        run_view --scene spheres $extra --size 320x200 --frames 1 --snapshot view.png
        viewargs=$(sed -n 's/^view: //p' view.out)
        for want in $(grep -o -- '--[a-z-]* [^ ]*' <<<"$extra" | tr ' ' '='); do
            grep -qe " ${want/=/ }" <<<" $viewargs" || fail "the view lacks ${want/=/ }: $viewargs"
        done
        panel=$(sed -n 's/.*panel at \([0-9]*\),\([0-9]*\) size \([0-9]*\)x\([0-9]*\).*/\1,\2,\3,\4/p' \
                view.err)
        # shellcheck disable=SC2086 # the view is a list of options
        "$render" --scene spheres $viewargs --out render.png
        "$python" "$src/tests/viewer/compare.py" view.png render.png --skip "$panel" ||
            fail "the images differ outside the panel ($extra)"
    done
    ;;
options)
    # expect STATUS NEEDLE ARGS...: umbra-view ARGS exits with STATUS and stdout+stderr hold NEEDLE.
    expect() {
        local want=$1 needle=$2 got=0
        shift 2
        timeout 60 "$view" "$@" >out 2>&1 || got=$?
        # What umbra-render's parser or set-up prints names the program it runs in.
        if [ "$got" -ne "$want" ] || ! grep -qF -- "$needle" out || grep -q '^umbra-render:' out
        then
            sed 's/^/    /' out
            fail "umbra-view $* exited with $got (want $want), looked for: $needle"
        fi
        echo "ok:   exit $got: umbra-view $*"
    }
    expect 0 "--snapshot OUT.png" --help
    expect 0 "--technique NAME" --help
    expect 0 "umbra-view $(sed -n 's/^project(umbra VERSION \([0-9.]*\).*/\1/p' "$src/CMakeLists.txt")" \
        --version
    expect 0 "--map-size auto|N" --help
    expect 1 "umbra-view: --frames '0' is not a whole number in [1, 100000]" --frames 0
    expect 1 "umbra-view: --frames '0' is not a whole number in [1, 100000]" --fram=0
    expect 1 "umbra-view: --snapshot 'a.jpg': the name must end in .png" --snap a.jpg
    expect 1 "umbra-view: option '--no-g' is ambiguous: --no-gui, --no-ground" --no-g
    expect 1 "umbra-view: --no-gui takes no value" --no-gui=1
    expect 1 "--frames '12x' is not a whole number" --frames 12x
    expect 1 "--frames '-3' is not a whole number" --frames -3
    expect 1 "--orbit 'sun' is not camera or light" --orbit sun
    expect 1 "--snapshot 'a.jpg': the name must end in .png" --snapshot a.jpg
    expect 1 "--snapshot needs a value" --snapshot
    expect 1 "umbra-view: unknown option '--bogus'" --bogus
    expect 1 "umbra-view: --size '0x10' is not WxH" --size 0x10
    expect 1 "umbra-view: --out 'x.jpg': the extension must be .png or .exr" --out x.jpg
    expect 1 "umbra-view: UMBRA_ERROR_INVALID_ARGUMENT: umbra_shadow_desc_set_param: deep" \
        --technique deep --nodes 1
    expect 1 "umbra-view: UMBRA_ERROR_IO: umbra_volume_load_nrrd: cannot open \"nope.nrrd\"" \
        --volume nope.nrrd
    # No display: the window cannot open, a failure (2) that says so.
    got=0
    env -u DISPLAY -u WAYLAND_DISPLAY timeout 60 "$view" --scene-size 16 --size 16x16 >out 2>&1 ||
        got=$?
    { [ "$got" -eq 2 ] && grep -q "GLFW could not start" out; } ||
        { cat out; fail "without a display: exit $got (want 2 and a GLFW message)"; }
    echo "ok:   exit 2 without a display"
    ;;
*)
    fail "unknown case"
    ;;
esac
echo "viewer.sh $case: ok"
