#!/usr/bin/env bash
# ON THE GPU MACHINE from the repository root, with .deps/debs and .deps/base_src.tgz carried
# (git archive BASE | gzip > .deps/base_src.tgz): this tree against BASE in one call, for the
# training-speed A/Bs of docs/measurements (gpu_host_side, gpu_tile_lists).
#   [TESTS=regex] [HOST_PROFILE=0] [DEADLINE_S=520] bash scripts/gpu/ab_full_method.sh
# 1. Builds both trees side by side (the baseline: the sadsplat target only).
# 2. This tree's CUDA tests (ctest -R TESTS; default the rasterizer, CUDA, on-device, L0-force
#    and tile-list tests).
# 3. The full method on city 0 with the built-in pseudo-labels (--drop full, 7000 iterations),
#    base and new alternating, two passes; the first pass of each evaluated.
# 4. HOST_PROFILE=1: this tree's full method once more with --profile-host
#    ($OUT/profile_host_full_new.md).
# 5. Net-1 without screen-size pruning on city 0, base then new, while DEADLINE_S is not reached.
# $OUT/ab.txt gets the times (with any `[tile lists]` line of a training), metrics and test
# results; $OUT/ctest.log the test log.
set -uo pipefail
source "$(dirname "$0")/lib.sh"
s=$(date +%s)
t() { echo "[$(( $(date +%s) - s )) s] $*" >> "$OUT/ab.txt"; }
tile_lists() { tr '\r' '\n' < "$1" | grep 'tile lists'; }
gpu_build > /tmp/b_new.txt 2>&1 & p1=$!
(GPU_BUILD_TARGET=sadsplat gpu_baseline .deps/base_src.tgz) > /tmp/b_base.txt 2>&1 & p2=$!
wait $p1; r1=$?; wait $p2; r2=$?
t "builds new rc $r1 base rc $r2"
[ $r1 = 0 ] || tail -30 "$OUT/gpu_build.log" >> "$OUT/ab.txt"
B=/tmp/ab-base/build-gpu/bin
cache=$(scene_cache city_0 800x450 $B/sadsplat); pl=$(pl_cache "$cache" $B/sadsplat); t "caches"
mkdir -p /tmp/logs && mv "$OUT"/gpu_* "$OUT"/*.log /tmp/logs/ 2>/dev/null
OMP_NUM_THREADS=2 ctest --test-dir build-gpu -R "${TESTS:-Raster|Cuda|OnDevice|Gpu|L0Force|TileList}" \
  -j 8 --output-on-failure > /tmp/tests.log 2>&1
t "tests rc $? $(grep 'tests passed' /tmp/tests.log)"
grep -E 'FAILED|Failure|Expected|Which is|Skipped' /tmp/tests.log | head -30 >> "$OUT/ab.txt"
for pass in 1 2; do
  for side in base new; do
    b=build-gpu/bin; [ $side = base ] && b=$B
    log=/tmp/train_${side}_$pass.log
    $b/sadsplat train "$pl" --out /tmp/r_${side}_$pass --device cuda --iterations 7000 --drop full > "$log" 2>&1
    t "full $side pass $pass: $(train_summary "$log") $(tile_lists "$log")"
    if [ $pass = 1 ]; then
      $b/sadsplat eval /tmp/r_${side}_$pass > /tmp/eval_$side.json 2>/dev/null
      metrics_line $side /tmp/eval_$side.json >> "$OUT/ab.txt"
    fi
  done
done
if [ "${HOST_PROFILE:-0}" = 1 ]; then
  build-gpu/bin/sadsplat train "$pl" --out /tmp/host --device cuda --iterations 7000 --drop full \
    --profile-host > /tmp/host.log 2>&1
  t "host profile new: $(train_summary /tmp/host.log)"
  cp /tmp/host/profile.md "$OUT/profile_host_full_new.md"
fi
echo '{"max_screen_radius": 100000}' > /tmp/nosr.json
for side in base new; do
  b=build-gpu/bin; [ $side = base ] && b=$B
  [ $(( $(date +%s) - s )) -lt "${DEADLINE_S:-520}" ] || break
  log=/tmp/net1_${side}.log
  $b/sadsplat train "$cache" --out /tmp/n_${side} --device cuda --iterations 7000 --drop none \
    --config /tmp/nosr.json > "$log" 2>&1
  t "net1 nosr $side: $(train_summary "$log") $(tile_lists "$log")"
done
mv "$OUT"/gpu_* "$OUT"/*.log /tmp/logs/ 2>/dev/null
cp /tmp/tests.log "$OUT/ctest.log"
cat "$OUT/ab.txt"
