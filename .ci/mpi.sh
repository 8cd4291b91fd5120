#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# CI: umbra_mpi (-DUMBRA_WITH_MPI=ON) in a build directory of its own: Debian's Open MPI installed
# if missing, the libraries, umbra-render-mpi and the MPI tests built with warnings as errors, and
# those tests run (oversubscribed: the machine has 2 cores). The rest of that build's suite is
# the default build's, already run.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v mpicc >/dev/null || ! command -v mpirun >/dev/null; then
  apt-get update -qq && apt-get install -y -qq libopenmpi-dev openmpi-bin >/dev/null
fi
rm -rf build-mpi
cmake -S . -B build-mpi -DCMAKE_BUILD_TYPE=Release -DUMBRA_WERROR=ON -DUMBRA_WITH_MPI=ON \
      -DUMBRA_BUILD_BENCH=OFF -DUMBRA_BUILD_EXAMPLES=OFF -DUMBRA_BUILD_VIEWER=OFF >/dev/null
time cmake --build build-mpi -j2 --target test_mpi umbra-render-mpi umbra-render umbra_image_diff
time ctest --test-dir build-mpi --output-on-failure -R '^(test_mpi_|cli_mpi)'
