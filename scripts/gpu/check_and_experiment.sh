#!/usr/bin/env bash
# Run ON THE GPU MACHINE from the repository root: builds build-gpu/, runs the CUDA tests (those
# named in TESTS, a ctest regex) beside the drop experiments of one scene (scripts/gpu/experiments.sh)
# and the SSIM benchmark, all inside one call of about LIMIT seconds.
#   LIMIT=590 TESTS='cuda|Cuda' [SOLO='RUN ...' SOLO_SECONDS=150] \
#     bash scripts/gpu/check_and_experiment.sh KIND SEED JOBS RUN...
# $OUT gets build.log, ctest.log, bench_ssim.txt and what experiments.sh writes.
set -uo pipefail
start=$(date +%s)
out="${OUT:-/tmp/sadsplat-gpu-out}"
mkdir -p "$out"
bash scripts/gpu/build.sh > "$out/build.log" 2>&1 || { tail -40 "$out/build.log"; exit 1; }
export LD_LIBRARY_PATH="/tmp/sadsplat-deps/usr/lib/x86_64-linux-gnu:${LD_LIBRARY_PATH:-}"
echo "built in $(( $(date +%s) - start )) s"
# The fused SSIM decides the loss of every training below: check it first; if it fails, the
# trainings use the reference SSIM (infix _refssim) and say so.
ssim_ok=1
(cd build-gpu && ctest -R 'ImageMetrics' --output-on-failure > "$out/ctest_ssim.log" 2>&1) || ssim_ok=0
echo "fused SSIM test: $([ $ssim_ok = 1 ] && echo passed || echo FAILED, trainings use the reference SSIM)"
if [ -n "${TESTS:-}" ]; then
  (cd build-gpu && OMP_NUM_THREADS=2 timeout 300 ctest -j 6 -R "$TESTS" --output-on-failure \
     > "$out/ctest.log" 2>&1) &
fi
build-gpu/bin/sadsplat_bench_ssim --repeats 50 2>&1 | tee "$out/bench_ssim.txt"
kind="$1"; seed="$2"; jobs="$3"; shift 3
runs=()
for r in "$@"; do
  [ $ssim_ok = 1 ] && runs+=("$r") || runs+=("${r%_*}_refssim_${r##*_}")
done
left=$(( ${LIMIT:-590} - ${SOLO_SECONDS:-0} - ($(date +%s) - start) ))
RUN_SECONDS=0 bash scripts/gpu/experiments.sh "$kind" "$seed" "$jobs" "$left" "${runs[@]}"
# SOLO: runs trained one at a time afterwards, for clean training times (name infix _solo).
if [ -n "${SOLO:-}" ]; then
  solo=()
  for r in $SOLO; do
    [ $ssim_ok = 1 ] && solo+=("${r%_*}_solo_${r##*_}") || solo+=("${r%_*}_refssim_solo_${r##*_}")
  done
  left=$(( ${LIMIT:-590} - ($(date +%s) - start) ))
  RUN_SECONDS=0 bash scripts/gpu/experiments.sh "$kind" "$seed" 1 "$left" "${solo[@]}"
fi
wait
[ -f "$out/ctest.log" ] && tail -15 "$out/ctest.log"
echo "call total $(( $(date +%s) - start )) s"
