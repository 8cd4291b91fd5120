#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# tests/mpi/cli.sh MPIEXEC UMBRA_RENDER_MPI UMBRA_RENDER IMAGE_DIFF: umbra-render-mpi on 4 ranks
# (2x2x1) against umbra-render on a generated volume file, for none, threshold, CSSM and deep
# (deep at epsilon 0 and 0.02; EXR images, early termination off: --termination 1), and
# --composite chain bit for bit for none, threshold and CSSM; the stats name every rank; the techniques
# that do not split and a grid that does not tile are refused with one message, exit status 1.
set -euo pipefail
mpiexec=$1 mpi=$2 one=$3 diff=$4
work=$(mktemp -d "${TMPDIR:-/tmp}/umbra-cli-mpi.XXXXXX")
trap 'rm -rf "$work"' EXIT
fail() { echo "cli.sh: FAIL: $*" >&2; exit 1; }
run4() { "$mpiexec" -np 4 --oversubscribe "$mpi" "$@"; }

# A 64^3 uint8 volume: two blobs and a ripple, written with its NRRD header.
python3 - "$work" <<'PY'
import math, sys
n = 64
out = bytearray(n * n * n)
i = 0
for z in range(n):
    for y in range(n):
        for x in range(n):
            a = math.exp(-((x - 26) ** 2 + (y - 30) ** 2 + (z - 34) ** 2) / 200.0)
            b = 0.8 * math.exp(-((x - 44) ** 2 + (y - 20) ** 2 + (z - 22) ** 2) / 80.0)
            s = a + b + 0.1 * math.sin(0.5 * x + 0.3 * z) * math.cos(0.4 * y)
            out[i] = max(0, min(255, int(255 * s)))
            i += 1
open(sys.argv[1] + "/blobs.raw", "wb").write(out)
open(sys.argv[1] + "/blobs.nhdr", "w").write(
    "NRRD0004\ntype: uint8\ndimension: 3\nsizes: 64 64 64\nencoding: raw\ndata file: blobs.raw\n")
PY

common=(--volume "$work/blobs.nhdr" --size 64x48 --no-ground --termination 1 --shading
        --light-dir 0.3,-1,0.4 --map-size 128)
# The deep map at epsilon 0 and at its default 0.02 (the parts go on from the whole march state,
# the compression's included: the same bound, docs/distributed.md).
for t in none threshold cssm deep deep:0.02; do
  bound=1e-5; [ "$t" = none ] && bound=1e-6
  tech=(--technique "${t%%:*}")
  [ "$t" = deep ] && tech+=(--epsilon 0)
  [ "$t" = deep:0.02 ] && { tech+=(--epsilon 0.02); t=deep_eps; }
  "$one" "${common[@]}" "${tech[@]}" -o "$work/one_$t.exr" 2>/dev/null ||
    fail "umbra-render --technique $t"
  if ! run4 --grid 2x2x1 "${common[@]}" "${tech[@]}" -o "$work/mpi_$t.exr" 2>"$work/log_$t"; then
    cat "$work/log_$t" >&2
    fail "umbra-render-mpi --technique $t"
  fi
  for r in 0 1 2 3; do
    grep -qE "^ +$r +[0-9]+,[0-9]+,[0-9]+ " "$work/log_$t" || fail "$t: the stats lack rank $r"
  done
  echo -n "$t: "
  "$diff" "$work/one_$t.exr" "$work/mpi_$t.exr" "$bound" || fail "$t: the images differ"
done

# --composite chain: each rank goes on from the ranks in front, one device's image bit for bit.
for t in none threshold cssm; do
  run4 --grid 2x2x1 "${common[@]}" --technique "$t" --composite chain -o "$work/chain_$t.exr" \
    2>"$work/log_chain_$t" || { cat "$work/log_chain_$t" >&2; fail "$t: --composite chain"; }
  echo -n "$t, chain: "
  "$diff" "$work/one_$t.exr" "$work/chain_$t.exr" 0 || fail "$t, chain: not bit for bit"
done

# Refused on every rank, one message (printed by rank 0), exit status 1.
for bad in "--technique reference:reference does not split" \
           "--technique convolution:convolution does not split" \
           "--grid 3x1x1:must tile"; do
  opt=${bad%%:*} want=${bad#*:}
  set +e
  # shellcheck disable=SC2086
  out=$(run4 --grid 2x2x1 "${common[@]}" $opt -o "$work/bad.png" 2>&1)
  rc=$?
  set -e
  [ "$(grep -c "$want" <<<"$out")" = 1 ] || { echo "$out" >&2; fail "$opt: not one message '$want'"; }
  [ $rc -ne 0 ] || fail "$opt: exit status 0"
done
echo "cli.sh: PASS"
