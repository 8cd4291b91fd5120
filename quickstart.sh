#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# Installs what is missing (Debian 12 packages), builds umbra, and renders the built-in default
# scene ("spheres") without and with the exact reference shadows into out/.
# Usage: ./quickstart.sh [build-dir]      (default build-dir: build)
set -euo pipefail
cd "$(dirname "$0")"
build=${1:-build}

packages=(build-essential cmake pkg-config ocl-icd-opencl-dev opencl-headers opencl-c-headers
          pocl-opencl-icd libteem-dev libopenimageio-dev libnifti2-dev libcjson-dev
          libtiff-dev libexpat1-dev libcmocka-dev gnuplot-nox python3-dev python3-venv
          python3-numpy python3-pytest python3-nibabel python3-pil python3-pydicom
          libglfw3-dev libimgui-dev xvfb xauth libgl1-mesa-dri)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "quickstart: installing ${missing[*]}" >&2
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -q
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DUMBRA_WERROR=ON
cmake --build "$build" -j"$(nproc)"

mkdir -p out
"$build"/umbra-render --scene spheres --technique none --out out/spheres_none.png
"$build"/umbra-render --scene spheres --technique reference --out out/spheres_reference.png
echo "quickstart: wrote out/spheres_none.png and out/spheres_reference.png" >&2
