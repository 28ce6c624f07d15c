#!/usr/bin/env bash
# Run ON THE GPU MACHINE from the repository root, with .deps/debs carried:
#   bash scripts/gpu/build_and_test.sh [extra ctest args]
# Builds (scripts/gpu/build.sh) and runs the test suite; logs go to $OUT when set.
set -euo pipefail
out="${OUT:-/tmp/sadsplat-gpu-out}"
bash "$(dirname "$0")/build.sh"
export LD_LIBRARY_PATH="/tmp/sadsplat-deps/usr/lib/x86_64-linux-gnu:${LD_LIBRARY_PATH:-}"
ctest --test-dir build-gpu --output-on-failure -j 8 "$@" 2>&1 | tee "$out/gpu_ctest.log"
