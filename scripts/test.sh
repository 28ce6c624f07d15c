#!/usr/bin/env bash
# Installs what is missing (Debian bookworm, root), builds everything, runs the test suite, then
# runs it once more built with AddressSanitizer + UndefinedBehaviorSanitizer
# (scripts/sanitizer_tests.sh; SADSPLAT_SKIP_SANITIZERS=1 skips that second pass).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup_debian.sh
# A unity build (sources compiled in batches of 8): each LibTorch-heavy translation unit costs
# seconds of header parsing and instantiation alone, so batching halves a clean build on 2 cores.
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON
cmake --build build
ctest --test-dir build --output-on-failure -j 2
if [ "${SADSPLAT_SKIP_SANITIZERS:-0}" != 1 ]; then
  bash scripts/sanitizer_tests.sh
fi
