#!/usr/bin/env bash
# Build; the long schedule on the real survey with the drop from the start (L1) or densification
# until 3500 (L2); city 0 7000-iteration probes with shorter densification.
set -u
export CALL_START=$(date +%s)
source scripts/gpu/lib.sh
gpu_build || exit 1
echo "built at $(( $(date +%s) - CALL_START )) s"
for d in 2000 2500 3500; do echo "{\"densify_until\": $d}" > /tmp/d$d.json; done
export OMP_NUM_THREADS=2
( ITERATIONS=30000 bash scripts/gpu/experiments.sh scene "$PWD/.deps/real/brighton_800.cache" 2 560 \
  "structure_long_from0:--drop structure --schedule long --lambda-l0-from 0" \
  "structure_long_d3500:--drop structure --schedule long --config /tmp/d3500.json" > /tmp/brighton.log 2>&1 ) &
sleep 3
bash scripts/gpu/experiments.sh scene city_0_pl 4 540 \
  "full:--drop full" \
  "full_d2000:--drop full --config /tmp/d2000.json" \
  "late_d2000_s5:--drop full --config /tmp/d2000.json --lambda-l0-from 2000 --recovery 1000 --l0-strength 5" \
  "late_d2500_s4:--drop full --config /tmp/d2500.json --lambda-l0-from 2500 --recovery 1000 --l0-strength 4"
wait
tail -6 /tmp/brighton.log
rm -f "$OUT"/gpu_configure.log "$OUT"/gpu_env.log "$OUT"/synth_*.log "$OUT"/pseudo_labels_*.log; ls "$OUT"
echo "call at $(( $(date +%s) - CALL_START )) s"
