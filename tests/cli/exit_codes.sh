#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# tests/cli/exit_codes.sh UMBRA_RENDER: umbra-render's exit statuses and strict number parsing
# against docs/usage.md ("bad input exits 1 with a message naming the problem; a failure on the
# device exits 2"), issue 11 rows 2, 10 and 11. Each case runs the CLI on a tiny image and checks
# the status, a piece of the message, and for output paths that nothing was rendered first.
set -uo pipefail
render=$(realpath "${1:?usage: exit_codes.sh path/to/umbra-render}")
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cd "$tmp" # a case that wrongly succeeds writes its default umbra.png here, not into the tree
failures=0
small=(--scene-size 16 --size 16x16)

# expect STATUS NEEDLE [--no-render] -- ARGS...: runs umbra-render ARGS (90 s at most: a FIFO
# that blocks shows as a timeout) and checks its exit status and that stderr holds NEEDLE.
expect() {
    local want=$1 needle=$2 no_render=0
    shift 2
    if [[ $1 == --no-render ]]; then no_render=1; shift; fi
    [[ $1 == -- ]] && shift
    timeout 90 "$render" "$@" >"$tmp/out" 2>"$tmp/err"
    local got=$?
    local ok=1
    [[ $got -eq $want ]] || ok=0
    grep -qF -- "$needle" "$tmp/err" || ok=0
    if [[ $no_render -eq 1 ]] && grep -q '^render:\|^device:' "$tmp/err"; then ok=0; fi
    if [[ $ok -eq 0 ]]; then
        echo "FAIL: umbra-render $* -> exit $got (want $want), stderr:"
        sed 's/^/    /' "$tmp/err"
        echo "    (looked for: $needle)"
        failures=$((failures + 1))
        return 1
    fi
    echo "ok:   exit $got: umbra-render $*"
}

# Row 10: --device P:D is the documented index form, not a name.
expect 0 "wrote" -- "${small[@]}" --device 0:0 --out "$tmp/a.png"
expect 1 "P:D indices must be whole numbers in [0, 1023]" -- --device 0:4294967296
expect 2 "UMBRA_ERROR_NO_DEVICE" -- "${small[@]}" --device 7:7 --out "$tmp/a.png"
# Row 10: output paths are checked before anything is rendered, and are bad input.
expect 1 "the extension must be .png or .exr" --no-render -- "${small[@]}" --out "$tmp/a.jpg"
expect 1 "does not exist" --no-render -- "${small[@]}" --out "$tmp/no/such/dir/a.png"
mkdir "$tmp/dir.png"
expect 1 "is a directory" --no-render -- "${small[@]}" --out "$tmp/dir.png"
# Row 10: a request the technique cannot do, found at render time, is bad input too.
expect 1 "UMBRA_ERROR_UNSUPPORTED" -- "${small[@]}" --technique convolution --light-dir 0,0,1 \
    --out "$tmp/a.png"
expect 1 "UMBRA_ERROR_INVALID_ARGUMENT" -- "${small[@]}" --technique deep --map-size 9 \
    --out "$tmp/a.png"
expect 1 "cssm ray_block 4 must be 0" -- "${small[@]}" --technique cssm --ray-block 4 \
    --out "$tmp/a.png"
expect 0 "wrote" -- "${small[@]}" --technique cssm --ray-block 1 --out "$tmp/a.png"
# --interaction: off or auto (a single frame is the full map either way: nothing moved before it).
expect 0 "wrote" -- "${small[@]}" --technique deep --interaction auto --out "$tmp/a.png"
expect 1 "--interaction 'on' is neither off nor auto" --no-render -- "${small[@]}" \
    --interaction on --out "$tmp/a.png"
# Row 10: out of memory is a failure (2) wherever it happens, also while loading the volume. A
# sparse 4 GiB file (no disk used) under a 3 GB address-space limit makes the voxel buffer fail.
# Not under AddressSanitizer (.ci/sanitize.sh), whose shadow memory cannot live under ulimit -v.
if ! ldd "$render" 2>/dev/null | grep -q libasan && truncate -s 4G "$tmp/big.raw" 2>/dev/null; then
    (ulimit -v 3000000 && expect 2 "UMBRA_ERROR_OUT_OF_MEMORY" -- --raw "$tmp/big.raw" \
        --raw-dims 2048x2048x1024 --raw-type uint8 --size 16x16 --out "$tmp/a.png") ||
        failures=$((failures + 1))
    rm -f "$tmp/big.raw"
fi
# Row 11: whole numbers are parsed strictly: no wrap-around, no sign, no trailing text.
expect 1 "--raw-dims '4294967312x16x16' is not XxYxZ" -- --raw "$tmp/a.raw" \
    --raw-dims 4294967312x16x16 --raw-type uint8
expect 1 "--raw-dims '-1x16x16' is not XxYxZ" -- --raw "$tmp/a.raw" --raw-dims -1x16x16 \
    --raw-type uint8
expect 1 "--size '4294967360x64' is not WxH with whole numbers in [1, 16384]" -- \
    --size 4294967360x64
expect 1 "--size '64x64junk'" -- --size 64x64junk
expect 1 "--size ' 64x64'" -- --size " 64x64"
expect 1 "--size '+64x64'" -- --size +64x64
expect 1 "--seed '4294967296' is not a whole number" -- --seed 4294967296
expect 1 "--seed '-1' is not a whole number" -- --seed -1
expect 1 "--scene-size '16 ' is not a whole number" -- --scene-size "16 "
# Row 2: a FIFO as an input is refused at once (exit 1), not waited on (timeout: exit 124).
mkfifo "$tmp/fifo"
expect 1 "not a regular file" -- "${small[@]}" --tf "$tmp/fifo" --out "$tmp/a.png"
expect 1 "not a regular file" -- --raw "$tmp/fifo" --raw-dims 2x2x2 --raw-type uint8 \
    --size 16x16 --out "$tmp/a.png"
ln -s "$tmp/fifo" "$tmp/fifo.nrrd"
expect 1 "not a regular file" -- --volume "$tmp/fifo.nrrd" --size 16x16 --out "$tmp/a.png"
# #29 item 1: a header's data file outside its directory is refused (exit 1, naming the file)
# unless --allow-data-root names where it lies (tests/test_data_files.c checks the voxels).
mkdir "$tmp/hdr" "$tmp/elsewhere"
head -c 4096 /dev/urandom >"$tmp/elsewhere/secret.raw"
printf 'NDims = 3\nDimSize = 16 16 16\nElementType = MET_UCHAR\nElementDataFile = %s\n' \
    "$tmp/elsewhere/secret.raw" >"$tmp/hdr/abs.mhd"
printf 'NRRD0004\ntype: uchar\ndimension: 3\nsizes: 16 16 16\nencoding: raw\n%s\n' \
    'data file: ../elsewhere/secret.raw' >"$tmp/hdr/up.nhdr"
for h in abs.mhd up.nhdr; do
    expect 1 "outside \"$tmp/hdr\" (the header's directory)" -- \
        --volume "$tmp/hdr/$h" --size 16x16 --out "$tmp/a.png"
    expect 0 "wrote" -- --volume "$tmp/hdr/$h" --allow-data-root "$tmp/elsewhere" --size 16x16 \
        --out "$tmp/a.png"
done
expect 1 "outside every data root given" -- --volume "$tmp/hdr/up.nhdr" \
    --allow-data-root "$tmp/hdr" --size 16x16 --out "$tmp/a.png"
expect 1 "--allow-data-root needs a value" -- --allow-data-root

# #31: render modes, clipping, multi-channel raw files and label maps.
expect 0 "wrote" -- "${small[@]}" --mode mip --clip-plane 0,1,0,0 --crop 0,0,0,12,15,15 \
    --out "$tmp/a.png"
expect 1 "--mode 'max' is not composite, mip, minip or average" -- --mode max
expect 1 "render mode 'average' is a projection without light" -- "${small[@]}" --mode average \
    --technique threshold --out "$tmp/a.png"
expect 1 "--clip-plane '1,0,0' is not A,B,C,D" -- --clip-plane 1,0,0
planes=()
for i in 1 2 3 4 5 6 7; do planes+=(--clip-plane "1,0,0,$i"); done
expect 1 "at most 6 --clip-plane" -- "${planes[@]}"
expect 1 "plane 0 (0, 0, 0, 1) must be finite with a non-zero normal" -- "${small[@]}" \
    --clip-plane 0,0,0,1 --out "$tmp/a.png"
expect 1 "--crop '1,2,3' is not X0,Y0,Z0,X1,Y1,Z1" -- --crop 1,2,3
expect 1 "crop box along x [5, 2] voxels" -- "${small[@]}" --crop 5,0,0,2,8,8 --out "$tmp/a.png"
head -c 2048 /dev/zero >"$tmp/two.raw"
expect 0 "wrote" -- --raw "$tmp/two.raw" --raw-dims 8x8x8 --raw-type uint16 --raw-channels 2 \
    --size 16x16 --out "$tmp/a.png"
expect 1 "holds 2048 bytes, expected 3072" -- --raw "$tmp/two.raw" --raw-dims 8x8x8 \
    --raw-type uint16 --raw-channels 3 --size 16x16 --out "$tmp/a.png"
expect 1 "--raw-channels '5' is not a whole number in [1, 4]" -- --raw-channels 5
expect 1 "--raw-channels and --labels describe a --raw file" -- "${small[@]}" --labels \
    --out "$tmp/a.png"
expect 0 "wrote" -- --raw "$tmp/two.raw" --raw-dims 16x16x8 --raw-type uint8 --labels \
    --technique deep --size 16x16 --out "$tmp/a.png"
expect 1 "a label map has one channel of uint8 or uint16 labels" -- --raw "$tmp/two.raw" \
    --raw-dims 8x8x8 --raw-type float32 --labels --size 16x16 --out "$tmp/a.png"
printf '0 1 1 1 0\n1 1 1 1 0.5\n' >"$tmp/c.tf"
expect 1 "2 --channel-tf for a volume of 1 channel" -- "${small[@]}" --channel-tf "$tmp/c.tf" \
    --channel-tf "$tmp/c.tf" --out "$tmp/a.png"

if [[ $failures -ne 0 ]]; then
    echo "$failures case(s) failed"
    exit 1
fi
echo "all cases passed"
