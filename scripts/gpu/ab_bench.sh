#!/usr/bin/env bash
# Run ON THE GPU MACHINE from the repository root: the rasterizer benchmark of this tree against
# a baseline tree, in the same run (times drift 5-15 % between runs of the machine; the ratio
# measured in one run is what compares).
#   [BASE=.deps/base_src.tgz] [PASSES=2] bash scripts/gpu/ab_bench.sh [sadsplat_bench_rasterizer args]
# BASE is a source tarball of the baseline: git archive --format=tar REV | gzip > .deps/base_src.tgz
# Builds this tree (build-gpu/) and the baseline (/tmp/ab-base/build-gpu/), runs the CUDA tests of
# this tree's rasterizer against the CPU reference, then both benchmarks alternating, PASSES
# times each. $OUT gets ab_bench.txt and the logs.
set -euo pipefail
out="${OUT:-/tmp/sadsplat-gpu-out}"
mkdir -p "$out"
base="${BASE:-.deps/base_src.tgz}"
passes="${PASSES:-2}"
bash scripts/gpu/build.sh > "$out/build_new.log" 2>&1 || { tail -30 "$out/build_new.log"; exit 1; }
rm -rf /tmp/ab-base && mkdir -p /tmp/ab-base && tar -xzf "$base" -C /tmp/ab-base
ln -s "$PWD/.deps" /tmp/ab-base/.deps
# This tree's build script: it shares the unpacked packages with the build above.
cp scripts/gpu/build.sh /tmp/ab-base/scripts/gpu/build.sh
(cd /tmp/ab-base && OUT=/tmp/ab-base/logs bash scripts/gpu/build.sh > "$out/build_base.log" 2>&1) &
base_build=$!
export LD_LIBRARY_PATH="/tmp/sadsplat-deps/usr/lib/x86_64-linux-gnu:${LD_LIBRARY_PATH:-}"
OMP_NUM_THREADS=4 build-gpu/bin/test_gaussians --gtest_filter='*Raster*:*Cuda*:ImageMetrics.*' \
  > "$out/ab_tests.log" 2>&1 || { grep -E 'FAILED|Failure' "$out/ab_tests.log" | head -20; }
tail -1 "$out/ab_tests.log"
wait $base_build || { tail -30 "$out/build_base.log"; exit 1; }
summary="$out/ab_bench.txt"
echo "== $(date -u +%F) rasterizer, this tree vs baseline ($base), $(nvidia-smi --query-gpu=name --format=csv,noheader | head -1)" > "$summary"
for pass in $(seq "$passes"); do
  for side in new base; do
    bin=build-gpu/bin/sadsplat_bench_rasterizer
    [ "$side" = base ] && bin=/tmp/ab-base/build-gpu/bin/sadsplat_bench_rasterizer
    echo "-- $side, pass $pass" >> "$summary"
    "$bin" --device cuda "$@" >> "$summary" 2>&1
  done
done
cat "$summary"
