#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# bench/device/pack.sh: here, on a Debian 12 machine with the project's packages, builds
# umbra-bench for a machine that has none of them (a lent GPU host: a driver, no compiler
# packages, no network) and gathers into .gpu/ (ignored through .git/info/exclude; the device
# tool carries it) what bench/device/gpu.sh needs there:
#   .gpu/bin/umbra-bench  umbra_io without OpenImageIO (UMBRA_IO_IMAGES=OFF: no --save, no image
#                         cache there) and the plain-C twin at x86-64-v3, not this -march=native
#   .gpu/lib/             the shared libraries it loads beyond glibc and the OpenCL loader
#   .gpu/lib-opencl/      ocl-icd's loader, for a host that has none of its own
#   .gpu/data/            the volumes of bench/scenes/*.scene, from UMBRA_DATA_DIR
set -euo pipefail
cd "$(dirname "$0")/../.."
dir=.gpu
data=${UMBRA_DATA_DIR:-../shared/data/volumes}
build=build-gpu
cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DUMBRA_IO_IMAGES=OFF \
      -DUMBRA_BUILD_TOOLS=OFF -DUMBRA_BUILD_TESTS=OFF -DUMBRA_BUILD_EXAMPLES=OFF \
      -DUMBRA_INSTALL=OFF -DUMBRA_CPU_REFERENCE_ARCH=x86-64-v3 >/dev/null
cmake --build "$build" -j"$(nproc)" --target umbra-bench >/dev/null
rm -rf "$dir"
mkdir -p "$dir/bin" "$dir/lib" "$dir/lib-opencl" "$dir/data"
cp "$build/umbra-bench" "$dir/bin/"
# Each library under its soname, which is what the program asks the loader for; glibc's own
# stay behind (the host's newer glibc serves a program linked against Debian 12's).
ldd "$build/umbra-bench" | awk '$2 == "=>" && $3 ~ /^\// {print $1, $3}' |
  while read -r soname path; do
    case "$soname" in
      libc.so.*|libm.so.*|libpthread.so.*|libdl.so.*|librt.so.*|ld-linux*) continue ;;
      libOpenCL.so.*) cp -L "$path" "$dir/lib-opencl/$soname" ;;
      *) cp -L "$path" "$dir/lib/$soname" ;;
    esac
  done
for v in $(awk '$1 == "volume" && $2 ~ /\.nhdr$/ {print $2}' bench/scenes/*.scene); do
  raw=$(awk '/^data file:/ {print $3}' "$data/$v")
  for f in "$data/$v" "$data/$raw"; do
    [ -f "$f" ] || { echo "pack.sh: $f missing (set UMBRA_DATA_DIR)" >&2; exit 1; }
    cp "$f" "$dir/data/"
  done
done
du -sh "$dir"
