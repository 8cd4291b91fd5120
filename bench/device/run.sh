#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# bench/device/run.sh OUT_DIR [args for time_techniques]: builds libumbra alone (no umbra_io, no
# tests: a compiler, CMake and an OpenCL loader are all it needs) into build-device/, builds
# time_techniques against it, and writes its table to OUT_DIR/techniques.md.
# OPENCL_INCLUDE / OPENCL_LIBRARY point at the OpenCL headers and loader where they are not in
# the system's paths (on a GPU machine without the Debian packages).
set -euo pipefail
cd "$(dirname "$0")/../.."
out=${1:?usage: run.sh OUT_DIR [scene res width height frames]}
shift
mkdir -p "$out"
cl_args=()
[ -n "${OPENCL_INCLUDE:-}" ] && cl_args+=(-DOpenCL_INCLUDE_DIR="$OPENCL_INCLUDE")
[ -n "${OPENCL_LIBRARY:-}" ] && cl_args+=(-DOpenCL_LIBRARY="$OPENCL_LIBRARY")
cmake -S . -B build-device -DCMAKE_BUILD_TYPE=Release -DUMBRA_BUILD_IO=OFF -DUMBRA_BUILD_TOOLS=OFF \
      -DUMBRA_BUILD_TESTS=OFF -DUMBRA_BUILD_BENCH=OFF -DUMBRA_BUILD_EXAMPLES=OFF \
      -DUMBRA_INSTALL=OFF "${cl_args[@]}" >/dev/null
cmake --build build-device -j"$(nproc)" --target umbra_static >/dev/null
inc=(-Iinclude -Ibuild-device/generated/include)
[ -n "${OPENCL_INCLUDE:-}" ] && inc+=(-I"$OPENCL_INCLUDE")
lib=${OPENCL_LIBRARY:--lOpenCL}
cc -std=c11 -O2 -Wall -Wextra -DCL_TARGET_OPENCL_VERSION=120 "${inc[@]}" \
   -o build-device/time_techniques bench/device/time_techniques.c build-device/libumbra.a \
   "$lib" -lm -lpthread
build-device/time_techniques "$@" | tee "$out/techniques.md"
