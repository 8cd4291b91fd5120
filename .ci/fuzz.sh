#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# CI: a short run (60 s each) of the three libFuzzer harnesses (tests/fuzz) on their seed corpora,
# built with clang, ASan and UBSan in build-fuzz/. Installs clang and its fuzzer runtime if they
# are missing. A longer run is documented in docs/testing.md.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v clang-14 >/dev/null && ! command -v clang >/dev/null ||
   ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
    sudo=""
    [[ $(id -u) -eq 0 ]] || sudo=sudo
    $sudo apt-get update -qq
    $sudo apt-get install -y -qq clang libclang-rt-dev
fi
rm -rf build-fuzz
time tests/fuzz/run.sh 60
