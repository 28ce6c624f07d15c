#!/usr/bin/env bash
# The call of this folder (run from the repository root on the GPU machine, .deps/debs carried).
set -uo pipefail
echo '{"densify_until": 5000}' > /tmp/d5.json
echo '{"densify_until": 6000}' > /tmp/d6.json
echo '{"use_pseudo_labels": false}' > /tmp/nopl.json
export GPU_BUILD_TARGET=sadsplat
L='--lambda-l0-from 3500 --recovery 1000'
bash scripts/gpu/experiments.sh scene city_0_pl 4 470 'none:--drop none --config /tmp/nopl.json' \
  'full:--drop full' 'full_d5:--drop full --config /tmp/d5.json' 'full_d6:--drop full --config /tmp/d6.json' \
  "late_s5:--drop full $L --l0-strength 5" "late_s4_d5:--drop full $L --l0-strength 4 --config /tmp/d5.json" \
  "late_s6_d5:--drop full $L --l0-strength 6 --config /tmp/d5.json" 'full_rec_d5:--drop full --recovery 1000 --config /tmp/d5.json'
mkdir -p /tmp/o && mv ${OUT:-/tmp/sadsplat-gpu-out}/gpu_*.log /tmp/o/ 2>/dev/null; true
