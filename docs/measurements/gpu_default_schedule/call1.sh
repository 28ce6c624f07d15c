#!/usr/bin/env bash
# Build; the CUDA tests of the SH-count header and the schedule; then the `defaults` table.
set -u
export CALL_START=$(date +%s)
source scripts/gpu/lib.sh
gpu_build || exit 1
echo "[$(( $(date +%s) - CALL_START )) s] built"
export OMP_NUM_THREADS=2
for k in city_0 country_0 port_0; do ( c=$(scene_cache $k) && pl_cache "$c" > /dev/null ) & done
( OMP_NUM_THREADS=1 ctest --test-dir build-gpu --output-on-failure -j 6 \
    -R 'RasterizerCuda|TrainerOnDevice|TrainConfig|CudaTileLists|Cuda|SemanticLoss|ImageMetrics' \
    > "$OUT/gpu_ctest.log" 2>&1; echo "ctest rc $?" >> "$OUT/gpu_ctest.log" ) &
wait
echo "[$(( $(date +%s) - CALL_START )) s] scenes made, tests: $(tail -4 $OUT/gpu_ctest.log | tr '\n' ' ')"
MIN_RUN_S=200 bash scripts/gpu/experiments.sh table defaults 9 565
rm -f "$OUT"/gpu_build*.log "$OUT"/gpu_configure*.log "$OUT"/synth_*.log "$OUT"/pseudo_labels_*.log; ls "$OUT"
echo "call at $(( $(date +%s) - CALL_START )) s"
