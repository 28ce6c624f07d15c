#!/usr/bin/env bash
set -u
export CALL_START=$(date +%s)
source scripts/gpu/lib.sh
gpu_build || exit 1
SCENE=${SCENE:-country_0}
for d in 1500 2000 2500; do echo "{\"densify_until\": $d}" > /tmp/d$d.json; done
export OMP_NUM_THREADS=2
( bash scripts/gpu/experiments.sh scene $SCENE 2 560 "net1:--drop none" "net1_d2000:--drop none --config /tmp/d2000.json" > /tmp/nopl.log 2>&1 ) &
sleep 2
bash scripts/gpu/experiments.sh scene ${SCENE}_pl 4 560 \
  "full:--drop full" \
  "late_d2000_s5:--drop full --config /tmp/d2000.json --lambda-l0-from 2000 --recovery 1000 --l0-strength 5" \
  "late_d2000_s6:--drop full --config /tmp/d2000.json --lambda-l0-from 2000 --recovery 1000 --l0-strength 6" \
  "late_d2000_s7:--drop full --config /tmp/d2000.json --lambda-l0-from 2000 --recovery 1000 --l0-strength 7"
wait
cat /tmp/nopl.log | grep -v "^$" | tail -6
rm -f "$OUT"/gpu_*.log "$OUT"/synth_*.log "$OUT"/pseudo_labels_*.log; ls "$OUT"
echo "call at $(( $(date +%s) - CALL_START )) s"
