#!/usr/bin/env bash
# Run ON THE GPU MACHINE from the repository root, with .deps/debs copied along:
#   bash scripts/gpu/build_and_test.sh [extra ctest args]
# Builds (scripts/gpu/build.sh) and runs the test suite; logs go to $OUT when set.
set -euo pipefail
out="${OUT:-/tmp/sadsplat-gpu-out}"
bash "$(dirname "$0")/build.sh"
export LD_LIBRARY_PATH="/tmp/sadsplat-deps/usr/lib/x86_64-linux-gnu:${LD_LIBRARY_PATH:-}"
# Eight test processes of LibTorch's default 16 intra-op threads each oversubscribed the 16 cores
# (round 6: CPU trainer tests took 140-312 s there, ~1 s on a 2-core dev machine, and the suite
# ran past 330 s): give each process its share of the cores.
jobs=8
export OMP_NUM_THREADS=$(( $(nproc) / jobs > 0 ? $(nproc) / jobs : 1 ))
ctest --test-dir build-gpu --output-on-failure -j "$jobs" "$@" 2>&1 | tee "$out/gpu_ctest.log"
