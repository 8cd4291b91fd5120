#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# tests/consumer/check.sh SOURCE_DIR BUILD_DIR: umbra as an application takes it in.
#  1. `cmake --install` into a fresh prefix; no installed file, binaries included, names the source
#     or build tree; the installed umbra-render finds an installed preset by name.
#  2. The consumers (a copy of this folder, outside the source tree) build and run against the
#     prefix alone through find_package(umbra), then through pkg-config (umbra, umbra-io, and the
#     static libraries with --static), then with umbra as an add_subdirectory of theirs.
#  3. A program linked only against umbra::umbra loads no OpenImageIO, Teem, ffmpeg or GDAL.
#  4. The shared libraries export the public umbra_* API and nothing else.
#  5. umbra_io configured with UMBRA_IO_IMAGES=OFF loads no OpenImageIO, still loads volumes and
#     refuses images with UMBRA_ERROR_UNSUPPORTED; umbra-bench builds against it (it is how
#     bench/device/pack.sh carries the bench to a GPU machine).
set -euo pipefail
src=$(cd "$1" && pwd)
build=$(cd "$2" && pwd)
work=$(mktemp -d "${TMPDIR:-/tmp}/umbra-consumer.XXXXXX")
trap 'rm -rf "$work"' EXIT
fail() { echo "check.sh: FAIL: $*" >&2; exit 1; }
jobs=$(nproc 2>/dev/null || echo 2)

echo "== install into a fresh prefix"
prefix=$work/prefix
cmake --install "$build" --prefix "$prefix" >/dev/null
libdir=$(dirname "$(find "$prefix" -name 'libumbra.so' | head -n1)")
[ -n "$libdir" ] || fail "no libumbra.so installed"
for f in libumbra.so libumbra.a libumbra_io.so libumbra_io.a cmake/umbra/umbraConfig.cmake \
         cmake/umbra/umbraConfigVersion.cmake pkgconfig/umbra.pc pkgconfig/umbra-io.pc; do
  [ -e "$libdir/$f" ] || fail "not installed: $libdir/$f"
done
soname=$(objdump -p "$libdir/libumbra.so" | awk '/SONAME/ {print $2}')
case "$soname" in libumbra.so.[0-9]*) ;; *) fail "libumbra.so has no versioned soname ($soname)";; esac
for f in umbra.h io.h config.h context.h registry.h techniques/list.h techniques/cssm.h; do
  [ -f "$prefix/include/umbra/$f" ] || fail "header not installed: include/umbra/$f"
done
[ -x "$prefix/bin/umbra-render" ] || fail "umbra-render not installed"
"$prefix/bin/umbra-render" --version | grep -q "umbra-render" || fail "umbra-render --version"
for f in paraview.json LICENSE; do
  [ -f "$prefix/share/umbra/presets/$f" ] || fail "not installed: share/umbra/presets/$f"
done
# The installed tool finds an installed preset by name, from a directory that holds none.
(cd "$work" && env -u UMBRA_PRESET_PATH "$prefix/bin/umbra-render" --tf "Cool to Warm" \
   --technique none --size 16x16 --out "$work/preset.png" 2>/dev/null) ||
  fail "the installed umbra-render does not find the preset \"Cool to Warm\" by name"
# Every installed file, binaries included (-a): a path left by __FILE__ or the debug information
# names the machine that built it (CMakeLists.txt maps both trees away with -ffile-prefix-map).
named=$(grep -rlaF -e "$src" -e "$build" "$prefix" || true)
if [ -n "$named" ]; then
  for f in $named; do
    echo "$f: $(grep -aoF -e "$src" -e "$build" "$f" | wc -l) occurrences, e.g." \
         "$(strings -a "$f" | grep -F -e "$src" -e "$build" | head -n1)" >&2
  done
  fail "the installed files above name the source or build tree"
fi
echo "no installed file ($(find "$prefix" -type f | wc -l) of them) names $src or $build"
cp -r "$src/tests/consumer" "$work/consumer"

echo "== find_package(umbra) from the prefix"
cmake -S "$work/consumer" -B "$work/fp" -DCMAKE_PREFIX_PATH="$prefix" \
      -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/fp" -j"$jobs" >/dev/null
"$work/fp/consumer_c"
"$work/fp/consumer_cxx" "$work/fp.png"
[ -s "$work/fp.png" ] || fail "consumer_cxx wrote no image"

echo "== pkg-config"
export PKG_CONFIG_PATH=$libdir/pkgconfig
# Without CL_TARGET_OPENCL_VERSION, as most applications include it: nothing printed, no note
# from CL/cl_version.h either.
cc -std=c11 -Wall -Wextra -Werror -o "$work/pc_c" "$work/consumer/consumer.c" \
   $(pkg-config --cflags --libs umbra) -Wl,-rpath,"$libdir" 2>"$work/pc_c.log" ||
  { cat "$work/pc_c.log" >&2; fail "consumer.c does not build through pkg-config"; }
[ ! -s "$work/pc_c.log" ] ||
  { cat "$work/pc_c.log" >&2; fail "including umbra.h printed the above"; }
"$work/pc_c"
c++ -std=c++17 -Wall -Wextra -Werror -DCL_TARGET_OPENCL_VERSION=300 -o "$work/pc_cxx" \
    "$work/consumer/consumer.cpp" $(pkg-config --cflags --libs umbra-io) -Wl,-rpath,"$libdir"
"$work/pc_cxx" "$work/pc.png"
# The static libraries, with what they need from pkg-config --static.
cc -std=c11 -o "$work/pc_static" "$work/consumer/consumer.c" \
   $(pkg-config --cflags umbra) "$libdir/libumbra.a" $(pkg-config --static --libs-only-l umbra | sed 's/-lumbra//')
"$work/pc_static"

echo "== add_subdirectory(umbra)"
cmake -S "$work/consumer" -B "$work/sub" -DUMBRA_SOURCE_DIR="$src" \
      -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/sub" -j"$jobs" >/dev/null
"$work/sub/consumer_c"
"$work/sub/consumer_cxx" "$work/sub.png"
for t in umbra-render umbra-bench test_io; do
  [ ! -e "$work/sub/umbra/$t" ] || fail "add_subdirectory built $t (only the libraries expected)"
done

echo "== a program on umbra::umbra alone loads no I/O library"
deps=$(ldd "$work/fp/consumer_c")
if grep -Eqi 'OpenImageIO|teem|nifti|znz|cjson|avcodec|avformat|gdal|opencv|dcmtk|openvdb' <<<"$deps"; then
  echo "$deps" >&2
  fail "consumer_c loads an I/O dependency"
fi
echo "consumer_c loads $(grep -c '=>' <<<"$deps") shared libraries"
"$work/fp/consumer_c" --idle
"$work/fp/consumer_cxx" --help >/dev/null 2>&1 || true

echo "== exports"
for lib in libumbra.so libumbra_io.so; do
  bad=$(nm -D --defined-only "$libdir/$lib" | awk '$2 ~ /^[TDBRVW]$/ {print $3}' | grep -v '^umbra_' || true)
  internal=$(nm -D --defined-only "$libdir/$lib" | awk '{print $3}' | grep '^umbra__' || true)
  [ -z "$bad$internal" ] || { echo "$bad$internal" >&2; fail "$lib exports more than the public API"; }
  echo "$lib exports $(nm -D --defined-only "$libdir/$lib" | grep -c ' umbra_') umbra_* symbols"
done
echo "== umbra_io without OpenImageIO (UMBRA_IO_IMAGES=OFF)"
noimg=$work/noimg
cmake -S "$src" -B "$noimg" -DCMAKE_BUILD_TYPE=Release -DUMBRA_IO_IMAGES=OFF \
      -DUMBRA_BUILD_TOOLS=OFF -DUMBRA_BUILD_TESTS=OFF -DUMBRA_BUILD_EXAMPLES=OFF \
      -DUMBRA_INSTALL=OFF >/dev/null
cmake --build "$noimg" -j"$jobs" --target umbra_io umbra-bench >/dev/null
if ldd "$noimg/libumbra_io.so" "$noimg/umbra-bench" | grep -qi OpenImageIO; then
  fail "the UMBRA_IO_IMAGES=OFF build loads OpenImageIO"
fi
cc -std=c11 -Wall -Wextra -Werror -DCL_TARGET_OPENCL_VERSION=120 -I"$src/include" \
   -I"$noimg/generated/include" \
   -o "$work/no_images" "$src/tests/consumer/no_images.c" -L"$noimg" -lumbra_io -lumbra \
   -lOpenCL -Wl,-rpath,"$noimg"
"$work/no_images" "$work"
echo "check.sh: all consumers built and ran"
