#!/usr/bin/env bash
# GPU checks for a machine with an NVIDIA GPU and nvcc: builds the device
# check programs straight with nvcc (they need only the kernel headers and
# GLM, not the renderer's libraries) and runs them:
#   tests/cuda/kernels_on_device.cu  samplers bit for bit, BSDFs to 1e-4, against the host
#   tests/cuda/bvh_on_device.cu      the portable BVH's traversal against the host, and its
#                                    rays per second on the device and on one host core
#   device_backend_on_device         with GPU_BUNDLE (made by scripts/gpu_bundle.sh on a machine
#                                    with the full build): the CUDA backend renders its fixtures,
#                                    unguided, table- and network-guided, against the host
#                                    emulation, with figures
# Usage: scripts/gpu_check.sh [OUT_DIR]   (GLM_INCLUDE: the folder holding glm/, default /usr/include;
# NVCC: the compiler, default /usr/local/cuda/bin/nvcc; CUDA_ARCH: default sm_90)
# Exit status: 0 all passed, 1 a check failed, 77 no device.
set -u -o pipefail
cd "$(dirname "$0")/.."
out=${1:-gpu-check}
mkdir -p "$out"
nvcc=${NVCC:-/usr/local/cuda/bin/nvcc}
flags=(-std=c++17 -O3 "-arch=${CUDA_ARCH:-sm_90}" --expt-relaxed-constexpr -diag-suppress=20012 -Isrc
       "-I${GLM_INCLUDE:-/usr/include}")
command -v nvidia-smi >/dev/null && nvidia-smi -L | tee "$out/device.txt"
# The CUDA backend first (prebuilt: it needs nothing built here).
status=0
if [ -n "${GPU_BUNDLE:-}" ]; then
  LD_LIBRARY_PATH="$GPU_BUNDLE${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" "$GPU_BUNDLE/device_backend_on_device" "$GPU_BUNDLE"/fixtures/*.fixture 2>&1 | tee "$out/device_backend_on_device.txt"
  rc=${PIPESTATUS[0]}
  echo "device_backend_on_device: exit $rc"
  if [ "$rc" -eq 77 ]; then status=77; elif [ "$rc" -ne 0 ]; then status=1; fi
fi
"$nvcc" "${flags[@]}" tests/cuda/kernels_on_device.cu -o "$out/kernels_on_device" || exit 1
"$nvcc" "${flags[@]}" tests/cuda/bvh_on_device.cu src/render/bvh_build.cpp -o "$out/bvh_on_device" || exit 1
for check in kernels_on_device bvh_on_device; do
  "$out/$check" 2>&1 | tee "$out/$check.txt"
  rc=${PIPESTATUS[0]}
  echo "$check: exit $rc"
  if [ "$rc" -eq 77 ]; then status=77; elif [ "$rc" -ne 0 ]; then status=1; fi
done
exit $status
