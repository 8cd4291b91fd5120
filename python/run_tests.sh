#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# python/run_tests.sh BUILD_DIR: the Python package's tests against Debian's NumPy (ctest runs
# this as test_python; .ci/wheel.sh runs them from the wheel against PyPI's).
# Builds and installs python/ with pip into a virtual environment in BUILD_DIR (Debian's pip
# refuses system installs, PEP 668) and runs its pytest suite, which compares against
# BUILD_DIR/umbra-render's pixels. The Debian packages it needs (python3-dev, -venv, -numpy,
# -pytest, -nibabel, -pil, -pydicom) are in quickstart.sh's list; pip fetches scikit-build-core and nanobind.
set -euo pipefail
cd "$(dirname "$0")/.."
build=$(cd "${1:-build}" && pwd)

# Debian's Python (not one earlier on PATH); NumPy, pytest, nibabel and Pillow come from Debian
# through --system-site-packages, the build tools (scikit-build-core, nanobind) from PyPI.
venv=$build/python-venv
rm -rf "$venv"
/usr/bin/python3 -m venv --system-site-packages "$venv"
# With OpenImageIO (Debian's), which the wheel leaves out: the tests then read umbra-render's EXR
# files with umbra's own reader and check umbra.to_srgb8 against its PNG writer.
CMAKE_BUILD_PARALLEL_LEVEL=$(nproc) "$venv"/bin/pip install --quiet \
  --config-settings=cmake.define.UMBRA_IO_IMAGES=ON ./python
export UMBRA_RENDER=$build/umbra-render
export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$build/pocl-cache}
src=$PWD
cd "$build"   # not the source tree, so that "import umbra" finds the installed package
"$venv"/bin/python -m pytest -q -p no:cacheprovider "$src/python/tests"
