#!/usr/bin/env bash
# Installs what is missing (Debian bookworm, root), builds, and runs `sadsplat demo`.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup_debian.sh
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON  # batched: faster clean build
cmake --build build --target sadsplat
./build/bin/sadsplat demo --out out/demo
