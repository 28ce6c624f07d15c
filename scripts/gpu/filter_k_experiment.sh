#!/usr/bin/env bash
# Run ON THE GPU MACHINE: does a looser pseudo-label filter (more coverage, mean + k std with
# k < 1) train better or worse than k = 1? One benchmark scene, all trainings in one call so
# that every row shares the same Net-1:
#   bash scripts/gpu/filter_k_experiment.sh KIND SEED [DEADLINE_S=560] [K ...]
# Default K: 1 0.5 0. Runs Net-1 (none_nopl) and, for each K, Net-3 (none_pl) with the default
# filter of `sadsplat pseudo-labels` (per class + cross-view) at --filter-k K; extra pseudo-label
# arguments from PL_ARGS; LAST_K_RUNS adds runs (names of experiments.sh, e.g. full_p1_pl) for the
# last K. Builds build-gpu/ if missing; the scene is generated once and shared.
# Output in $OUT: summary_KIND_SEED_kK.txt per K (scripts/gpu/experiments.sh) and results tarballs.
set -uo pipefail
kind="$1"; seed="$2"; deadline="${3:-560}"; shift $(( $# < 3 ? $# : 3 ))
ks=("$@"); [ ${#ks[@]} -gt 0 ] || ks=(1 0.5 0)
start=$(date +%s)
export OUT="${OUT:-/tmp/sadsplat-gpu-out}"
mkdir -p "$OUT"
if [ ! -x build-gpu/bin/sadsplat ]; then
  bash scripts/gpu/build.sh > "$OUT/gpu_build_full.log" 2>&1 || { tail -30 "$OUT/gpu_build_full.log"; exit 1; }
fi
echo "build ready after $(( $(date +%s) - start )) s"
export LD_LIBRARY_PATH="/tmp/sadsplat-deps/usr/lib/x86_64-linux-gnu:${LD_LIBRARY_PATH:-}"
mkdir -p /tmp/sadsplat-exp
shared=/tmp/sadsplat-exp/${kind}_${seed}_scene.cache
[ -f "$shared" ] || build-gpu/bin/sadsplat synth --kind "$kind" --seed "$seed" --width 800 --height 450 \
  --cache "$shared" > /dev/null
# Labels one variant at a time (each pseudo-labels run uses all cores), then all trainings at once.
for k in "${ks[@]}"; do
  mkdir -p "/tmp/sadsplat-exp/${kind}_${seed}_k$k"
  cp --update=none "$shared" "/tmp/sadsplat-exp/${kind}_${seed}_k$k/scene.cache"
  PL_ARGS="--filter-k=$k ${PL_ARGS:-}" PL_TAG="_k$k" bash scripts/gpu/experiments.sh "$kind" "$seed" 1 0 \
    > /dev/null 2>&1
done
echo "labels ready after $(( $(date +%s) - start )) s"
left=$(( deadline - ($(date +%s) - start) ))
first=1
for k in "${ks[@]}"; do
  runs=(none_pl); [ $first = 1 ] && runs=(none_nopl none_pl); first=0
  [ "$k" = "${ks[-1]}" ] && runs+=(${LAST_K_RUNS:-})
  PL_ARGS="--filter-k=$k ${PL_ARGS:-}" PL_TAG="_k$k" RUN_SECONDS=0 \
    bash scripts/gpu/experiments.sh "$kind" "$seed" 2 "$left" "${runs[@]}" > "$OUT/log_${kind}_${seed}_k$k.txt" 2>&1 &
done
wait
for k in "${ks[@]}"; do grep -h 'none_\|precision\|not started\|stopped' "$OUT/summary_${kind}_${seed}_k$k.txt" | head -4; done
# At most 8 files come back from a run on the GPU machine: the summaries stay, the rest goes into one tarball.
(cd "$OUT" && tar -czf "all_${kind}_${seed}.tar.gz" --remove-files results_*.tar.gz log_*.txt gpu_*.log 2>/dev/null)
echo "total $(( $(date +%s) - start )) s"
