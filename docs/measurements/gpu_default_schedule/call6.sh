#!/usr/bin/env bash
# The real survey at 400x225 under the defaults: Net-1 and --drop structure, two seeds.
set -u
export CALL_START=$(date +%s)
source scripts/gpu/lib.sh
gpu_build || exit 1
echo "[$(( $(date +%s) - CALL_START )) s] built"
export OMP_NUM_THREADS=2
bash scripts/gpu/experiments.sh scene $PWD/.deps/real/brighton_400.cache 4 250 \
  "net1_s42:--drop none --seed 42" "structure_s42:--drop structure --seed 42" \
  "net1_s1:--drop none --seed 1" "structure_s1:--drop structure --seed 1"
rm -f "$OUT"/gpu_build*.log "$OUT"/gpu_configure*.log; ls "$OUT"
echo "call at $(( $(date +%s) - CALL_START )) s"
