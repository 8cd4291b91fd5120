#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# CI: the Debug configuration (-O0) builds every target with warnings as errors (issue 11, row
# 15: GCC's -Wformat-truncation fires at -O0 where the Release build's value tracking is silent).
set -euo pipefail
cd "$(dirname "$0")/.."
rm -rf build-debug
cmake -S . -B build-debug -DCMAKE_BUILD_TYPE=Debug -DUMBRA_WERROR=ON >/dev/null
time cmake --build build-debug -j2
