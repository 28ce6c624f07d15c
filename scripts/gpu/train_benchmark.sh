#!/usr/bin/env bash
# Run ON THE GPU MACHINE after scripts/gpu/build.sh: generates a benchmark scene directly at the
# training resolution (800x450 = half of 1600x900) as a scene cache, trains it with CUDA and
# evaluates it. Results (metrics, logs, config) go to $OUT.
#   [TAG=name] bash scripts/gpu/train_benchmark.sh KIND SEED [ITERATIONS] [extra train args...]
# TAG distinguishes runs of one scene with different train args (e.g. --drop full --p-base 1).
set -euo pipefail
kind="$1"; seed="$2"; iterations="${3:-7000}"; shift $(( $# < 3 ? $# : 3 ))
out="${OUT:-/tmp/sadsplat-gpu-out}"
mkdir -p "$out"
export LD_LIBRARY_PATH="/tmp/sadsplat-deps/usr/lib/x86_64-linux-gnu:${LD_LIBRARY_PATH:-}"
bin=build-gpu/bin/sadsplat
work=/tmp/sadsplat-bench
mkdir -p "$work"
cache="$work/${kind}_${seed}_800x450.cache"
[ -f "$cache" ] || "$bin" synth --kind "$kind" --seed "$seed" --width 800 --height 450 --cache "$cache" \
  2>&1 | tee "$out/synth_${kind}_${seed}.log"
name="${kind}_${seed}${TAG:+_$TAG}"
run="$work/run_$name"
rm -rf "$run"
"$bin" train "$cache" --device cuda --iterations "$iterations" --out "$run" "$@" \
  > "$out/train_$name.log" 2>&1
tr '\r' '\n' < "$out/train_$name.log" | { grep -c '^\[drop\]' || true; } | sed 's/^/drop events: /'; tr '\r' '\n' < "$out/train_$name.log" | tail -2
"$bin" eval "$run" > "$out/metrics_$name.json"
cp "$run/config.json" "$out/config_$name.json"
python3 - "$out/metrics_$name.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
print("%s: mIoU %.2f  mAcc %.2f  OA %.2f  PSNR %.2f  SSIM %.3f  gaussians %d  train %.0f s" % (
    sys.argv[1].split('/')[-1], 100*m['miou'], 100*m['macc'], 100*m['oacc'], m['psnr'], m['ssim'],
    m['num_gaussians'], m['train_seconds']))
print("  per class:", {k: (round(100*v, 1) if v is not None else None) for k, v in m['per_class_iou'].items()})
PY
