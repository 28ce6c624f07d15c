#!/usr/bin/env bash
# The third call of this folder (run from the repository root on the GPU machine, .deps/debs carried).
set -uo pipefail
echo '{"use_pseudo_labels": false}' > /tmp/nopl.json
export GPU_BUILD_TARGET=sadsplat
L='--lambda-l0-from 3500 --recovery 1000'
bash scripts/gpu/experiments.sh scene city_0_pl 4 470 'none:--drop none --config /tmp/nopl.json' \
  'full:--drop full' "late_s5:--drop full $L --l0-strength 5" \
  "late_s5_rp3:--drop full $L --l0-strength 5 --recovery-prune 0.3" \
  "late_s5_rp5:--drop full $L --l0-strength 5 --recovery-prune 0.5" \
  "late_s4_rp5:--drop full $L --l0-strength 4 --recovery-prune 0.5" \
  'full_rp3:--drop full --recovery 1000 --recovery-prune 0.3' \
  "late_s6_rp3:--drop full $L --l0-strength 6 --recovery-prune 0.3"
mkdir -p /tmp/o && mv ${OUT:-/tmp/sadsplat-gpu-out}/gpu_*.log /tmp/o/ 2>/dev/null; true
