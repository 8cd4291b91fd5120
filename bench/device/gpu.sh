#!/usr/bin/env bash
# SPDX-License-Identifier: Apache-2.0
# bench/device/gpu.sh OUT [STEP...]: on the GPU machine, runs the umbra-bench that
# bench/device/pack.sh gathered into .gpu/, on the GPU's OpenCL (umbra picks a GPU first;
# UMBRA_SAMPLER=buffer|image overrides the volume sampler it picks). Steps, by default all:
#   raycast      umbra against the plain-C twin on the host's cores (VTK is not there)
#   builds       the light-space map builds at equal size
#   interactive  camera orbit, light orbit, opacity edits, drafts, per technique
#   accuracy     the full sweep against the exact reference, without images or plots
# Each writes OUT/STEP/ (the CSV and Markdown of its --results or --out); the log is OUT/log.
# The NVIDIA driver's OpenCL library is named in /etc/OpenCL/vendors where no .icd names it yet
# (the host is a bare machine given back after the session), and the host's own OpenCL loader
# is used where it has one: Debian 12's ocl-icd, carried, found no platform in NVIDIA's there.
set -uo pipefail
cd "$(dirname "$0")/../.."
out=${1:?usage: gpu.sh OUT [raycast] [builds] [interactive] [accuracy]}
shift
steps=${*:-raycast builds interactive accuracy}
mkdir -p "$out"
exec > >(tee -a "$out/log") 2>&1
lib="$PWD/.gpu/lib"
ldconfig -p | grep -q 'libOpenCL\.so\.1 ' || lib="$lib:$PWD/.gpu/lib-opencl"
export LD_LIBRARY_PATH="$lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export UMBRA_DATA_DIR="$PWD/.gpu/data"
bench="$PWD/.gpu/bin/umbra-bench"
nv=$(find /usr/lib /usr/lib64 /usr/local/nvidia -name 'libnvidia-opencl.so.1' 2>/dev/null |
     head -n1)
if [ -n "$nv" ] && ! grep -qs nvidia-opencl /etc/OpenCL/vendors/*.icd; then
  mkdir -p /etc/OpenCL/vendors && echo "$nv" >/etc/OpenCL/vendors/nvidia.icd
fi
echo "== $(date -u +%FT%TZ) host: $(nproc) cores; NVIDIA OpenCL: ${nv:-not found};" \
     "sampler: ${UMBRA_SAMPLER:-per device}"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.mem --format=csv 2>&1 | sed 's/^/   /'
"$bench" --version || exit 1

step() { # name seconds args...
  local name=$1 limit=$2
  shift 2
  echo "== $(date -u +%T) $name"
  local t0=$SECONDS
  timeout "$limit" "$bench" "$name" "$@"
  echo "== $name: exit $? after $((SECONDS - t0)) s"
}
for s in $steps; do
  case $s in
    raycast) step raycast 120 --results "$out/raycast" ;;
    builds) step builds 120 --scene-dir bench/scenes --results "$out/builds" ;;
    interactive) step interactive 300 --scene-dir bench/scenes --results "$out/interactive" ;;
    accuracy) step accuracy 400 --scene-dir bench/scenes --out "$out/accuracy" --images none \
                   --no-plots --no-cache ;;
    *) echo "gpu.sh: unknown step $s" >&2; exit 2 ;;
  esac
done
