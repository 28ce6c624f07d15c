#!/usr/bin/env bash
# A/B driver (run from the repository root on the GPU machine, with .deps/debs and
# .deps/base_src.tgz = `git archive BASE | gzip` carried along): this tree against BASE.
set -uo pipefail
source scripts/gpu/lib.sh
s=$(date +%s)
t() { echo "[$(( $(date +%s) - s )) s] $*" >> $OUT/ab.txt; }
gpu_build > /tmp/b_new.txt 2>&1 & p1=$!
rm -rf /tmp/ab-base && mkdir -p /tmp/ab-base && tar -xzf .deps/base_src.tgz -C /tmp/ab-base && ln -s "$PWD/.deps" /tmp/ab-base/.deps
(GPU_BUILD_TARGET=sadsplat gpu_build /tmp/ab-base _base) > /tmp/b_base.txt 2>&1 & p2=$!
wait $p1; r1=$?; wait $p2; r2=$?
t "builds new rc $r1 base rc $r2"
[ $r1 = 0 ] || tail -30 $OUT/gpu_build.log >> $OUT/ab.txt
B=/tmp/ab-base/build-gpu/bin
cache=$(scene_cache city_0 800x450 $B/sadsplat); pl=$(pl_cache "$cache" $B/sadsplat); t "caches"
mkdir -p /tmp/logs && mv $OUT/gpu_* $OUT/*.log /tmp/logs/ 2>/dev/null
OMP_NUM_THREADS=2 ctest --test-dir build-gpu -R 'Raster|Cuda|OnDevice|Gpu|L0Force|TileList' -j 8 --output-on-failure > /tmp/tests.log 2>&1; t "tests rc $? $(grep 'tests passed' /tmp/tests.log)"
grep -E 'FAILED|Failure|Expected|Which is|Skipped' /tmp/tests.log | head -30 >> $OUT/ab.txt
grep -E 'TileList' /tmp/tests.log | head >> $OUT/ab.txt
for pass in 1 2; do
  for side in base new; do
    b=build-gpu/bin; [ $side = base ] && b=$B
    $b/sadsplat train "$pl" --out /tmp/r_${side}_$pass --device cuda --iterations 7000 --drop full > /tmp/train_${side}_$pass.log 2>&1
    t "full $side pass $pass: $(train_summary /tmp/train_${side}_$pass.log) $(tr '\r' '\n' < /tmp/train_${side}_$pass.log | grep 'tile lists')"
    if [ $pass = 1 ]; then $b/sadsplat eval /tmp/r_${side}_$pass > /tmp/eval_$side.json 2>/dev/null; metrics_line $side /tmp/eval_$side.json >> $OUT/ab.txt; fi
  done
done
echo '{"max_screen_radius": 100000}' > /tmp/nosr.json
for side in base new; do
  b=build-gpu/bin; [ $side = base ] && b=$B
  [ $(( $(date +%s) - s )) -lt 520 ] || break
  $b/sadsplat train "$cache" --out /tmp/n_${side} --device cuda --iterations 7000 --drop none --config /tmp/nosr.json > /tmp/net1_${side}.log 2>&1
  t "net1 nosr $side: $(train_summary /tmp/net1_${side}.log) $(tr '\r' '\n' < /tmp/net1_${side}.log | grep 'tile lists')"
done
mv $OUT/gpu_* $OUT/*.log /tmp/logs/ 2>/dev/null
cp /tmp/tests.log $OUT/ctest.log
cat $OUT/ab.txt
