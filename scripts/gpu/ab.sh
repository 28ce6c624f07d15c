#!/usr/bin/env bash
# ON THE GPU MACHINE from the repository root: this tree against a baseline tree in the same call
# (machine starts differ by up to 30 %: only a ratio measured in one call compares).
#   [BASE=.deps/base_src.tgz] [PASSES=2] bash scripts/gpu/ab.sh bench [sadsplat_bench_rasterizer args]
#   [BASE=...] [PASSES=2] [SCENE=city_0] [PL=1] [DROP=full] bash scripts/gpu/ab.sh train [train args]
# BASE: git archive --format=tar REV | gzip > .deps/base_src.tgz (carried along).
#   bench  the CUDA rasterizer tests of this tree, then both rasterizer benchmarks alternating
#   train  SCENE at 800x450, 7000 iterations, --drop DROP (on the scene with the built-in
#          pseudo-labels when PL=1), one training at a time, alternating; nvidia-smi samples the
#          GPU's utilisation during this tree's last pass (util.csv); EVAL=1 evaluates the first
#          pass of each side (eval_new.json, eval_base.json). Caches already in /tmp/sadsplat-scenes
#          (<scene>_800x450.cache and, with PL=1, <scene>_800x450_pl.cache) are used as they are
# $OUT gets ab_bench.txt or ab_train.txt, and the logs.
set -uo pipefail
source "$(dirname "$0")/lib.sh"
mode="${1:?usage: ab.sh bench|train [args]}"; shift
base="${BASE:-.deps/base_src.tgz}"; passes="${PASSES:-2}"
gpu_build || exit 1
gpu_baseline "$base" > "$OUT/build_base.txt" 2>&1 || { cat "$OUT/build_base.txt"; exit 1; }
card=$(nvidia-smi --query-gpu=name --format=csv,noheader | head -1)
case "$mode" in
  bench)
    OMP_NUM_THREADS=4 build-gpu/bin/test_gaussians --gtest_filter='*Raster*:*Cuda*:ImageMetrics.*' \
      > "$OUT/ab_tests.log" 2>&1 || grep -E 'FAILED|Failure' "$OUT/ab_tests.log" | head -20
    tail -1 "$OUT/ab_tests.log"
    summary="$OUT/ab_bench.txt"
    echo "== $(date -u +%F) rasterizer, this tree vs baseline ($base), $card" > "$summary"
    for pass in $(seq "$passes"); do
      for side in new base; do
        bin=build-gpu/bin/sadsplat_bench_rasterizer
        [ "$side" = base ] && bin=$BASE_BIN_DIR/sadsplat_bench_rasterizer
        echo "-- $side, pass $pass" >> "$summary"
        "$bin" --device cuda "$@" >> "$summary" 2>&1
      done
    done ;;
  train)
    scene="${SCENE:-city_0}"; drop="${DROP:-full}"
    # The baseline writes the scene cache: a newer tree reads older cache versions, not the reverse.
    cache=$(scene_cache "$scene" 800x450 "$BASE_BIN_DIR/sadsplat") || exit 1
    [ "${PL:-1}" = 1 ] && { cache=$(pl_cache "$cache" "$BASE_BIN_DIR/sadsplat") || exit 1; }
    summary="$OUT/ab_train.txt"
    echo "== $(date -u +%F) training, this tree vs baseline ($base): $scene 800x450 7000 iterations --drop $drop PL=${PL:-1} $*, $card" > "$summary"
    for pass in $(seq "$passes"); do
      for side in base new; do
        b=$SADSPLAT_BIN; [ "$side" = base ] && b=$BASE_BIN_DIR/sadsplat
        run=/tmp/ab-train/run_${side}_$pass; rm -rf "$run"; mkdir -p /tmp/ab-train
        sampler=""
        if [ "$side" = new ] && [ "$pass" = "$passes" ]; then
          nvidia-smi --query-gpu=timestamp,utilization.gpu --format=csv,noheader -lms 200 > "$OUT/util.csv" &
          sampler=$!
        fi
        "$b" train "$cache" --out "$run" --device cuda --iterations 7000 --drop "$drop" "$@" \
          > "$OUT/train_${side}_$pass.log" 2>&1
        [ -n "$sampler" ] && kill "$sampler"
        echo "$side pass $pass: $(train_summary "$OUT/train_${side}_$pass.log")" >> "$summary"
        if [ "${EVAL:-0}" = 1 ] && [ "$pass" = 1 ]; then
          "$b" eval "$run" > "$OUT/eval_$side.json" 2>/dev/null
          metrics_line "$side" "$OUT/eval_$side.json" >> "$summary"
        fi
      done
    done
    (cd "$OUT" && tar czf ab_train_logs.tgz --remove-files train_*.log) ;;
  *) echo "unknown mode $mode (bench or train)"; exit 2 ;;
esac
cat "$summary"
