#!/usr/bin/env bash
# Run ON THE GPU MACHINE from the repository root (builds build-gpu/ if missing): data-parallel
# training over NCCL ranks against one GPU, on the large city-xl scene and on the ordinary city.
#   bash scripts/gpu/distributed_benchmark.sh [ITERATIONS=7000] [GPUS=2]
# RUNS (env, default: all) picks among
#   xl_1gpu        city-xl, one GPU, one view per step, ITERATIONS steps (the reference)
#   xl_1gpu_batch  city-xl, one GPU, GPUS views per step with --batch-schedule (the same
#                  arithmetic as GPUS ranks: ITERATIONS / GPUS steps)
#   xl_ranks       city-xl, GPUS NCCL ranks (--nproc GPUS --batch-schedule)
#   city_1gpu, city_ranks   the same on the 70-view city (seed 0): the overhead at small scale
#   xl_blocks      city-xl in BLOCKS (env, default 4) blocks one after another on GPU 0
#                  (--blocks), each for ITERATIONS steps; then scripts/block_borders.py against
#                  xl_1gpu on the views that straddle block borders
#   xl_blocks_ranks  the same blocks shared by GPUS ranks (--blocks --nproc GPUS)
#   xl_stream      as xl_1gpu with --stream-views (views read from the scene cache ahead of the
#                  steps that use them, uploaded per step)
#   xl_auto        --max-gpu-memory BUDGET (env, GiB, default 22): as few blocks as the estimate
#                  fits (views held); xl_auto_stream the same with --stream-views
# PRESET (env, default city-xl; city-xxl: 1,120 views over 16 city tiles) is the large scene.
# xl_1gpu and xl_1gpu_batch run at the same time on GPUs 0 and 1 when PAIR=1 (default 0).
# Method: the full drop (--drop full), no pseudo-labels (PSEUDO=1: pseudo-labelled caches, as the
# paper's full method); SIZE (env, default 800x450) caches made here by synth.
# VIEWS (env, default 1): views per step and rank in the batched runs (global batch GPUS x VIEWS).
# EXTRA_FLAGS (env) go to every training, e.g. --profile (then $OUT gets profile_<run>.md).
# Output names carry the shape: xl_ranks4x2 (4 ranks x 2 views), xl_1gpu_batch8 (8 views a step).
# $OUT gets summary.txt (wall time, Gaussians, peak GPU memory per GPU, peak host memory of
# rank 0's process, mIoU / PSNR), the logs
# and the metrics.
set -euo pipefail
source "$(dirname "$0")/lib.sh"   # NVLink multicast off (inherited by the ranks), build, scene caches
iterations="${1:-7000}"
gpus="${2:-2}"
out="$OUT"
[ -x "$SADSPLAT_BIN" ] || gpu_build || exit 1
bin=$SADSPLAT_BIN
work=/tmp/sadsplat-distributed
mkdir -p "$work"
summary="$out/summary.txt"
echo "== $(date -u +%F) iterations $iterations, $gpus GPUs: $(nvidia-smi --query-gpu=name --format=csv,noheader | head -1)" | tee -a "$summary"

wanted=" ${RUNS:-xl_1gpu xl_1gpu_batch xl_ranks city_1gpu city_ranks} "
xl=$(scene_cache "${PRESET:-city-xl}" "${SIZE:-800x450}")
if [ "${PSEUDO:-0}" = 1 ]; then xl=$(pl_cache "$xl"); fi
if [[ $wanted == *" city_"* ]]; then
  city=$(scene_cache city_0 "${SIZE:-800x450}")
  if [ "${PSEUDO:-0}" = 1 ]; then city=$(pl_cache "$city"); fi
fi

# Peak memory.used per GPU while a command runs (nvidia-smi, every 200 ms).
peak_memory() {
  awk -F', ' '{ if ($2 + 0 > peak[$1]) peak[$1] = $2 + 0 } END { for (g in peak) printf "gpu%s %d MiB ", g, peak[g] }' "$1"
}

# run NAME SCENE VISIBLE_GPUS [train flags...]: one training, timed, then eval.
run() {
  local name=$1 scene=$2 visible=$3; shift 3
  local dir="$work/$name"; rm -rf "$dir"
  nvidia-smi --query-gpu=index,memory.used --format=csv,noheader,nounits -lms 200 > "$out/mem_$name.csv" 2>/dev/null &
  local poll=$!
  local start; start=$(date +%s%N)
  CUDA_VISIBLE_DEVICES=$visible "$bin" train "$scene" --device cuda --drop full --out "$dir" "$@" ${EXTRA_FLAGS:-} \
    > "$out/train_$name.log" 2>&1 || echo "$name: training FAILED (rc $?)" | tee -a "$summary"
  local wall=$(( ($(date +%s%N) - start) / 1000000 ))
  kill "$poll" 2>/dev/null || true; wait "$poll" 2>/dev/null || true
  [ -f "$dir/profile.md" ] && cp "$dir/profile.md" "$out/profile_$name.md"
  local gaussians; gaussians=$(tr '\r' '\n' < "$out/train_$name.log" | grep -o 'gaussians [0-9]*' | tail -1)
  CUDA_VISIBLE_DEVICES=${visible%%,*} "$bin" eval "$dir" > "$out/metrics_$name.json" 2> "$out/eval_$name.log" || true
  local miou psnr
  # metrics.json's top-level keys (per_view also has a "psnr" per view).
  read -r miou psnr merged < <(python3 -c 'import json, sys
try: m = json.load(open(sys.argv[1])); print(m.get("miou"), m["psnr"], m["num_gaussians"])
except Exception: print("? ? ?")' "$dir/metrics.json")
  [ -f "$dir/blocks.json" ] && gaussians="gaussians $merged (merged)"
  # The largest Gaussian count any training (or block) reached, and the estimates it printed.
  local most; most=$({ cat "$dir"/train_log.jsonl "$dir"/blocks/*/train_log.jsonl 2>/dev/null || true; } |
    python3 -c 'import json, sys; print(max((json.loads(l).get("gaussians", 0) for l in sys.stdin if l.strip()), default=0))')
  gaussians="$gaussians, most $most"
  tr '\r' '\n' < "$out/train_$name.log" | grep -E "GiB estimated" | sed "s/^/  $name /" | tee -a "$summary" || true
  echo "$name: wall ${wall} ms, $(grep -o 'trained in [0-9.]* s' "$out/train_$name.log" || true), $gaussians, peak $(peak_memory "$out/mem_$name.csv"), $(grep -o 'peak host memory [0-9]* MiB' "$out/train_$name.log" || true), mIoU $miou, PSNR $psnr, flags: $*" | tee -a "$summary"
  if [ -f "$dir/blocks.json" ]; then cp "$dir/blocks.json" "$out/blocks_$name.json"; fi
}

views=${VIEWS:-1}
batch=$(( gpus * views ))
half=$(( iterations / batch ))
all_gpus=$(seq -s, 0 $(( gpus - 1 )))
if [ "${PAIR:-0}" = 1 ] && [[ $wanted == *" xl_1gpu "* && $wanted == *" xl_1gpu_batch "* ]]; then
  run xl_1gpu "$xl" 0 --iterations "$iterations" &
  run "xl_1gpu_batch$batch" "$xl" 1 --iterations "$iterations" --views-per-step "$batch" --batch-schedule &
  wait
else
  [[ $wanted == *" xl_1gpu "* ]] && run xl_1gpu "$xl" 0 --iterations "$iterations"
  [[ $wanted == *" xl_1gpu_batch "* ]] && run "xl_1gpu_batch$batch" "$xl" 0 --iterations "$iterations" --views-per-step "$batch" --batch-schedule
fi
[[ $wanted == *" xl_ranks "* ]] && run "xl_ranks${gpus}x$views" "$xl" "$all_gpus" --iterations "$iterations" --nproc "$gpus" --views-per-step "$views" --batch-schedule
[[ $wanted == *" city_1gpu "* ]] && run city_1gpu "$city" 0 --iterations "$iterations"
[[ $wanted == *" city_ranks "* ]] && run "city_ranks${gpus}x$views" "$city" "$all_gpus" --iterations "$iterations" --nproc "$gpus" --views-per-step "$views" --batch-schedule
[[ $wanted == *" xl_stream "* ]] && run xl_1gpu_stream "$xl" 0 --iterations "$iterations" --stream-views
[[ $wanted == *" xl_auto "* ]] && run xl_auto "$xl" 0 --iterations "$iterations" --max-gpu-memory "${BUDGET:-22}"
[[ $wanted == *" xl_auto_stream "* ]] && run xl_auto_stream "$xl" 0 --iterations "$iterations" --max-gpu-memory "${BUDGET:-22}" --stream-views
blocks=${BLOCKS:-4}
[[ $wanted == *" xl_blocks "* ]] && run "xl_blocks$blocks" "$xl" 0 --iterations "$iterations" --blocks "$blocks"
[[ $wanted == *" xl_blocks_ranks "* ]] && run "xl_blocks${blocks}_ranks$gpus" "$xl" "$all_gpus" --iterations "$iterations" --blocks "$blocks" --nproc "$gpus"
if [[ $wanted == *" xl_blocks "* ]]; then
  python3 scripts/block_borders.py "$work/xl_blocks$blocks" "$work/xl_1gpu" 2>&1 | tee -a "$summary" || true
fi
echo "(batch runs take $half steps of $batch views)" >> "$summary"
