#!/usr/bin/env bash
# ON THE GPU MACHINE from the repository root, with .deps/debs carried along:
#   bash scripts/gpu/build_and_test.sh [--build-only] [ctest args, e.g. -R 'Cuda|Raster']
# Builds build-gpu/ with CUDA (scripts/gpu/lib.sh) and runs the test suite, CUDA against the CPU
# reference included. $OUT gets gpu_env.log, gpu_build.log and gpu_ctest.log.
set -uo pipefail
source "$(dirname "$0")/lib.sh"
gpu_build || exit 1
[ "${1:-}" = --build-only ] && exit 0
# Eight test processes of LibTorch's default 16 intra-op threads each oversubscribed the 16 cores
# (CPU trainer tests took 140-312 s there, ~1 s on a 2-core machine): each gets its share.
jobs=8
export OMP_NUM_THREADS=$(( $(nproc) / jobs > 0 ? $(nproc) / jobs : 1 ))
ctest --test-dir build-gpu --output-on-failure -j "$jobs" "$@" > "$OUT/gpu_ctest.log" 2>&1
rc=$?
tail -15 "$OUT/gpu_ctest.log"
exit $rc
