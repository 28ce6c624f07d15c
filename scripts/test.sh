#!/usr/bin/env bash
# Installs what is missing (Debian bookworm, root), builds everything, runs the test suite.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup_debian.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build
ctest --test-dir build --output-on-failure -j 2
