#!/usr/bin/env bash
# Run ON THE GPU MACHINE from the repository root (builds build-gpu/ if missing): where the
# training time goes. For each scene KIND_SEED (default city_0), generated at 800x450 as a cache:
# the full method unprofiled (the clean wall time, then eval), the full method with --profile
# and Net-1 (--drop none) with --profile, one training at a time.
#   bash scripts/gpu/profile_training.sh [ITERATIONS=7000] [KIND_SEED ...]
# RUNS (env) picks among full_plain full_profile none_plain none_profile. PL=1 (env): the full
# runs train on the scene with the built-in pseudo-labels (the default method, Net-4); Net-1 never.
# CONFIG (env): a training configuration JSON passed to every run (e.g. {"fused_semantic_loss":
# false} to profile a reference path).
# $OUT gets profile_<scene>_<run>.md, train logs, metrics and summary.txt.
set -euo pipefail
iterations="${1:-7000}"; shift $(( $# < 1 ? $# : 1 ))
scenes=("$@"); [ ${#scenes[@]} -gt 0 ] || scenes=(city_0)
out="${OUT:-/tmp/sadsplat-gpu-out}"
mkdir -p "$out"
[ -x build-gpu/bin/sadsplat ] || bash scripts/gpu/build.sh > "$out/build.log" 2>&1 || { tail -30 "$out/build.log"; exit 1; }
export LD_LIBRARY_PATH="/tmp/sadsplat-deps/usr/lib/x86_64-linux-gnu:${LD_LIBRARY_PATH:-}"
bin=build-gpu/bin/sadsplat
work=/tmp/sadsplat-profile
mkdir -p "$work"
summary="$out/summary.txt"
for scene in "${scenes[@]}"; do
  kind=${scene%_*}; seed=${scene##*_}
  cache="$work/${scene}_800x450.cache"
  [ -f "$cache" ] || "$bin" synth --kind "$kind" --seed "$seed" --width 800 --height 450 \
    --cache "$cache" > "$out/synth_$scene.log" 2>&1
  pl_cache="$work/${scene}_800x450_pl.cache"
  if [ "${PL:-0}" = 1 ] && [ ! -f "$pl_cache" ]; then
    "$bin" pseudo-labels "$cache" --out "$pl_cache" > "$out/pseudo_labels_$scene.log" 2>&1
  fi
  for run in ${RUNS:-full_plain full_profile none_profile}; do
    drop=${run%_*}; flags=(); [ "${run#*_}" = profile ] && flags=(--profile)
    [ -n "${CONFIG:-}" ] && flags+=(--config "$CONFIG")
    scene_file="$cache"; [ "${PL:-0}" = 1 ] && [ "$drop" = full ] && scene_file="$pl_cache"
    dir="$work/${scene}_$run"; rm -rf "$dir"
    start=$(date +%s%N)
    "$bin" train "$scene_file" --device cuda --iterations "$iterations" --drop "$drop" --out "$dir" \
      "${flags[@]}" > "$out/train_${scene}_$run.log" 2>&1
    wall=$(( ($(date +%s%N) - start) / 1000000 ))
    gaussians=$(tr '\r' '\n' < "$out/train_${scene}_$run.log" | grep -o 'gaussians [0-9]*' | tail -1)
    echo "$scene $run: wall ${wall} ms (process), $(grep -o 'trained in [0-9.]* s' "$out/train_${scene}_$run.log"), $gaussians" | tee -a "$summary"
    [ -f "$dir/profile.md" ] && cp "$dir/profile.md" "$out/profile_${scene}_$run.md"
    if [ "${run#*_}" = plain ]; then
      "$bin" eval "$dir" > "$out/metrics_${scene}_$run.json" 2>"$out/eval_${scene}_$run.log" || true
    fi
  done
done
nvidia-smi --query-gpu=name,memory.used,memory.total --format=csv >> "$summary" 2>&1 || true
