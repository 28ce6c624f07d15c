#!/usr/bin/env bash
# Run ON THE GPU MACHINE from the repository root: training wall time of this tree against a
# baseline tree, in the same run, one training at a time, alternating (times drift 5-15 % between
# runs of the machine; the ratio measured in one run is what compares).
#   [BASE=.deps/base_src.tgz] [PASSES=2] [SCENE=city_0] [PL=1] [DROP=full] bash scripts/gpu/ab_train.sh
# BASE is a source tarball of the baseline: git archive --format=tar REV | gzip > .deps/base_src.tgz
# Each training: SCENE at 800x450, 7000 iterations, --drop DROP, on the scene with the built-in
# pseudo-labels when PL=1. During the last pass of this tree, nvidia-smi samples the GPU's
# utilisation every 200 ms. $OUT gets ab_train.txt, util.csv and the logs (as ab_train_logs.tgz).
set -euo pipefail
out="${OUT:-/tmp/sadsplat-gpu-out}"
mkdir -p "$out"
base="${BASE:-.deps/base_src.tgz}"
passes="${PASSES:-2}"; scene="${SCENE:-city_0}"; drop="${DROP:-full}"
logs=/tmp/ab-train-logs; rm -rf "$logs"; mkdir -p "$logs"
bash scripts/gpu/build.sh > "$logs/build_new.log" 2>&1 || { tail -30 "$logs/build_new.log"; exit 1; }
rm -rf /tmp/ab-base && mkdir -p /tmp/ab-base && tar -xzf "$base" -C /tmp/ab-base
ln -s "$PWD/.deps" /tmp/ab-base/.deps
cp scripts/gpu/build.sh /tmp/ab-base/scripts/gpu/build.sh
(cd /tmp/ab-base && OUT=/tmp/ab-base/logs bash scripts/gpu/build.sh > "$logs/build_base.log" 2>&1) ||
  { tail -30 "$logs/build_base.log"; exit 1; }
export LD_LIBRARY_PATH="/tmp/sadsplat-deps/usr/lib/x86_64-linux-gnu:${LD_LIBRARY_PATH:-}"
bin=build-gpu/bin/sadsplat
kind=${scene%_*}; seed=${scene##*_}
# The baseline writes the scene cache: a newer tree reads older cache versions, not the reverse.
maker=/tmp/ab-base/$bin
cache=/tmp/ab-train/${scene}.cache; mkdir -p /tmp/ab-train
[ -f "$cache" ] || "$maker" synth --kind "$kind" --seed "$seed" --width 800 --height 450 \
  --cache "$cache" > "$logs/synth.log" 2>&1
if [ "${PL:-1}" = 1 ]; then
  [ -f "${cache%.cache}_pl.cache" ] || "$maker" pseudo-labels "$cache" --out "${cache%.cache}_pl.cache" \
    > "$logs/pseudo_labels.log" 2>&1
  cache="${cache%.cache}_pl.cache"
fi
summary="$out/ab_train.txt"
echo "== $(date -u +%F) training, this tree vs baseline ($base): $scene 800x450 7000 iterations --drop $drop PL=${PL:-1}, $(nvidia-smi --query-gpu=name --format=csv,noheader | head -1)" > "$summary"
for pass in $(seq "$passes"); do
  for side in base new; do
    b=$bin; [ "$side" = base ] && b=/tmp/ab-base/$bin
    run=/tmp/ab-train/run_${side}_$pass; rm -rf "$run"
    sampler=""
    if [ "$side" = new ] && [ "$pass" = "$passes" ]; then
      nvidia-smi --query-gpu=timestamp,utilization.gpu --format=csv,noheader -lms 200 > "$out/util.csv" &
      sampler=$!
    fi
    "$b" train "$cache" --out "$run" --device cuda --iterations 7000 --drop "$drop" \
      > "$logs/train_${side}_$pass.log" 2>&1
    [ -n "$sampler" ] && kill "$sampler"
    echo "$side pass $pass: $(tr '\r' '\n' < "$logs/train_${side}_$pass.log" | grep -o 'trained in [0-9.]* s') $(tr '\r' '\n' < "$logs/train_${side}_$pass.log" | grep -o 'gaussians [0-9]*' | tail -1)" >> "$summary"
  done
done
tar czf "$out/ab_train_logs.tgz" -C "$logs" .
cat "$summary"
