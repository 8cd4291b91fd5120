#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# tests/fuzz/run.sh SECONDS [NAME...]: builds the libFuzzer harnesses (clang, ASan + UBSan) in
# build-fuzz/ if needed and runs each (tf_file, scene_file, volume; or the NAMEs given) for
# SECONDS on a working copy of its seed corpus (tests/fuzz/corpus/NAME, never written to). Crash
# inputs land in build-fuzz/artifacts/NAME/; the last lines of each run (executions, coverage) are
# printed and kept in build-fuzz/NAME.log. Exits non-zero if any fuzzer found a crash, leak or
# sanitizer report.
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${1:?usage: tests/fuzz/run.sh SECONDS [tf_file|scene_file|volume ...]}
shift
names=("$@")
[[ ${#names[@]} -gt 0 ]] || names=(tf_file scene_file volume)
build=${UMBRA_FUZZ_BUILD:-build-fuzz}
cc=${CC:-$(command -v clang-14 || command -v clang)}
cxx=${CXX:-$(command -v clang++-14 || command -v clang++)}

if [[ ! -f $build/CMakeCache.txt ]]; then
    CC=$cc CXX=$cxx cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        -DUMBRA_BUILD_FUZZERS=ON -DUMBRA_BUILD_TESTS=OFF -DUMBRA_BUILD_BENCH=OFF \
        -DUMBRA_BUILD_EXAMPLES=OFF >/dev/null
fi
targets=()
for n in "${names[@]}"; do targets+=("fuzz_$n"); done
cmake --build "$build" -j"${UMBRA_FUZZ_JOBS:-2}" --target "${targets[@]}" >/dev/null

export POCL_CACHE_DIR=${POCL_CACHE_DIR:-$PWD/$build/pocl-cache}
# Leaks are checked after every input (libFuzzer's -detect_leaks); tests/fuzz/lsan.supp names the
# one known leak inside Teem and says why it is there.
export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:allocator_may_return_null=1}
export LSAN_OPTIONS=${LSAN_OPTIONS:-suppressions=$PWD/tests/fuzz/lsan.supp:print_suppressions=0}
export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
status=0
for n in "${names[@]}"; do
    work=$build/corpus/$n
    mkdir -p "$work" "$build/artifacts/$n"
    cp -n tests/fuzz/corpus/"$n"/* "$work"/ 2>/dev/null || true
    echo "== fuzz_$n: $seconds s on $work"
    if "$build/tests/fuzz/fuzz_$n" -max_total_time="$seconds" -max_len=4096 -rss_limit_mb=4096 \
        -timeout=30 -print_final_stats=1 -artifact_prefix="$build/artifacts/$n/" "$work" \
        >"$build/$n.log" 2>&1; then
        grep -E '^#[0-9]+.*(DONE|pulse)|stat::number_of_executed_units|stat::peak_rss' \
            "$build/$n.log" | tail -3
    else
        status=1
        echo "fuzz_$n FAILED; the report:"
        grep -v '^#[0-9]' "$build/$n.log" | tail -40
    fi
done
exit $status
