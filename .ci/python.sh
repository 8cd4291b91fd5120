#!/usr/bin/env bash
# CI: the Python package. Installs the Debian packages it needs if missing, builds and installs
# python/ with pip into a virtual environment (Debian's pip refuses system installs, PEP 668),
# and runs its pytest suite, which compares against build/umbra-render's pixels.
# Runs from the repository root after .ci/run's build into build/.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(python3-dev python3-venv python3-numpy python3-pytest python3-nibabel
          python3-pil)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "python.sh: installing ${missing[*]}" >&2
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# Debian's Python (not one earlier on PATH); NumPy, pytest, nibabel and Pillow come from Debian
# through --system-site-packages, the build tools (scikit-build-core, nanobind) from PyPI.
venv=$PWD/build/python-venv
rm -rf "$venv"
/usr/bin/python3 -m venv --system-site-packages "$venv"
CMAKE_BUILD_PARALLEL_LEVEL=$(nproc) "$venv"/bin/pip install --quiet ./python
export UMBRA_RENDER=$PWD/build/umbra-render
export POCL_CACHE_DIR=$PWD/build/pocl-cache
cd build   # not the source tree, so that "import umbra" finds the installed package
"$venv"/bin/python -m pytest -q -p no:cacheprovider ../python/tests
