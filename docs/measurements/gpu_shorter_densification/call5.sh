#!/usr/bin/env bash
set -u
export CALL_START=$(date +%s)
source scripts/gpu/lib.sh
gpu_build || exit 1
echo '{"densify_until": 2000}' > /tmp/d2000.json
export OMP_NUM_THREADS=2
C=$PWD/.deps/real/brighton_800.cache
specs=()
for s in 42 1; do specs+=( \
  "net1_s$s:--drop none --seed $s" \
  "net1_d2000_s$s:--drop none --config /tmp/d2000.json --seed $s" \
  "structure_s$s:--drop structure --seed $s" \
  "structure_d2000_s$s:--drop structure --config /tmp/d2000.json --seed $s" \
  "structure_late_d2000_s5_s$s:--drop structure --config /tmp/d2000.json --lambda-l0-from 2000 --recovery 1000 --l0-strength 5 --seed $s" )
done
bash scripts/gpu/experiments.sh scene $C 5 560 "${specs[@]}"
rm -f "$OUT"/gpu_*.log "$OUT"/synth_*.log "$OUT"/pseudo_labels_*.log; ls "$OUT"
echo "call at $(( $(date +%s) - CALL_START )) s"
