#!/usr/bin/env bash
# ON THE GPU MACHINE from the repository root: where one training's GPU time goes, per CUDA kernel
# (Nsight Compute's gpu__time_duration, clocks left alone), and how busy the GPU is without it.
#
#   [CONFIG=file.json] bash scripts/gpu/kernel_profile.sh TAG SCENE [AT=5000] [WINDOW=5] [train args...]
#
# CONFIG: TrainConfig keys for every training of the profile (train args must not carry a
# --config of their own: the short runs below pass one).
# 1. The training alone (ITERATIONS, default 7000), nvidia-smi sampling the GPU's utilisation every
#    200 ms: the wall time per iteration.
# 2. Two short trainings under ncu (10 and 20 iterations) count the kernels of the setup and of one
#    iteration (their difference / 10).
# 3. The training under ncu, timing every kernel of about WINDOW iterations from about iteration AT
#    (the kernel counts of step 2 place the window; an iteration's count varies with its view's
#    role, so the window is approximate).
# $OUT gets kernels_TAG.txt (the per-kernel table: launches, total and mean µs, share) and
# kernels_TAG.csv (ncu's raw rows). Sum of kernel time per iteration against the wall time per
# iteration = how much of a step the GPU spends running kernels (ncu serialises kernels, so the
# sum has no overlap).
set -uo pipefail
source "$(dirname "$0")/lib.sh"
tag="${1:?usage: kernel_profile.sh TAG SCENE [AT] [WINDOW] [train args...]}"
scene="${2:?scene cache or directory}"
at="${3:-5000}"
window="${4:-5}"
shift $(( $# < 4 ? $# : 4 ))
iterations="${ITERATIONS:-7000}"
user_config=(); [ -n "${CONFIG:-}" ] && user_config=(--config "$CONFIG")
[ -x "$SADSPLAT_BIN" ] || gpu_build || exit 1
export PATH=/usr/local/cuda/bin:$PATH
ncu_bin=$(command -v ncu || ls /opt/nvidia/nsight-compute/*/ncu 2>/dev/null | head -1)
[ -n "$ncu_bin" ] || { echo "ncu not found" >&2; exit 1; }
work=/tmp/sadsplat-kernels/$tag
rm -rf "$work" && mkdir -p "$work"
summary="$OUT/kernels_$tag.txt"

# 1. Plain training, utilisation sampled (PLAIN=0 leaves it out).
if [ "${PLAIN:-1}" = 1 ]; then
  nvidia-smi --query-gpu=utilization.gpu --format=csv,noheader,nounits -lms 200 > "$work/util.txt" &
  smi=$!
  start=$(date +%s%N)
  "$SADSPLAT_BIN" train "$scene" --device cuda --iterations "$iterations" --out "$work/plain" \
    "${user_config[@]}" "$@" > "$work/plain.log" 2>&1
  wall_ms=$(( ($(date +%s%N) - start) / 1000000 ))
  kill "$smi" 2>/dev/null
  {
    echo "# $tag: $scene, $iterations iterations, args: $*"
    echo "plain training: process wall $wall_ms ms, $(train_summary "$work/plain.log")"
    python3 - "$work/util.txt" <<'PY'
import sys
v = [int(x) for x in open(sys.argv[1]).read().split() if x.isdigit()]
busy = [x for x in v if x > 0]
print(f"nvidia-smi utilisation (200 ms samples): {len(v)} samples, mean of nonzero samples "
      f"{sum(busy) / max(len(busy), 1):.1f} %")
PY
  } | tee "$summary"
else
  wall_ms=0; : > "$summary"
fi

count_rows() { python3 -c 'import csv,sys; r=[x for x in csv.reader(open(sys.argv[1])) if len(x) > 5 and x[0].isdigit()]; print(len(r))' "$1"; }

# 2. Kernels of the setup and of one iteration. A short run rescales the schedule (densification,
# drop, SH degree every few iterations); the short runs get the keys it would change at their
# full-length values, so that their first iterations are those of the full run. COUNT_SKIP (0)
# launches are left untimed at the start: it must stay below the launches of a 10-iteration run
# (the setup of the city at 800x450 with pseudo-labels has fewer than 2000).
count_skip="${COUNT_SKIP:-0}"
"$SADSPLAT_BIN" train "$scene" --device cuda --iterations 10 --out "$work/schedule" \
  "${user_config[@]}" "$@" > "$work/schedule.log" 2>&1
python3 - "$work/schedule.log" "$work/schedule.json" "${CONFIG:-}" <<'PY'
import json, re, sys
keys = {}
for line in open(sys.argv[1]):
    if line.startswith("schedule of a run of"):
        for key, default in re.findall(r" (\w+) (\S+) -> \S+;", line):
            keys[key] = json.loads(default)
if sys.argv[3]:
    keys.update(json.load(open(sys.argv[3])))  # the user's keys as the full runs have them
json.dump(keys, open(sys.argv[2], "w"))
print("short runs keep", keys)
PY
# ncu_times CSV SKIP COUNT TIMEOUT_S train args...: times each kernel of launches SKIP ..
# SKIP + COUNT (COUNT 0: all) of one training, one row per launch in CSV.
ncu_times() {
  local csv="$1" skip="$2" count="$3" limit="$4"; shift 4
  local range=(--launch-skip "$skip"); [ "$count" -gt 0 ] && range+=(--launch-count "$count")
  timeout "$limit" "$ncu_bin" --clock-control none --metrics gpu__time_duration.sum --csv \
    --page raw --print-units base "${range[@]}" --log-file "$csv" "$SADSPLAT_BIN" train "$scene" \
    --device cuda "$@"
}
ncu_run_short() {
  ncu_times "$work/count_$1.csv" "$count_skip" 0 200 --iterations "$1" \
    --config "$work/schedule.json" --out "$work/count_$1" "${@:2}" > "$work/count_$1.log" 2>&1
}
ncu_run_short 10 "$@"
ncu_run_short 20 "$@"
k10=$(count_rows "$work/count_10.csv")
k20=$(count_rows "$work/count_20.csv")
per_it=$(( (k20 - k10) / 10 ))
setup=$(( count_skip + k10 - 10 * per_it ))
echo "kernels timed after the first $count_skip: 10 iterations $k10, 20 iterations $k20 -> ~$per_it per iteration, ~$setup in the setup" | tee -a "$summary"
[ "$per_it" -gt 0 ] && [ "$k10" -gt 0 ] || { echo "cannot place the window (COUNT_SKIP too large?)"; tail -20 "$work/count_10.log"; exit 1; }

# 3. The window.
skip=$(( setup + at * per_it ))
count=$(( window * per_it ))
ncu_times "$OUT/kernels_$tag.csv" "$skip" "$count" "${WINDOW_TIMEOUT_S:-300}" \
  --iterations "$iterations" --out "$work/window" "${user_config[@]}" "$@" > "$work/window.log" 2>&1
echo "window: launches $skip .. $(( skip + count )) (~iterations $at .. $(( at + window )))" | tee -a "$summary"
python3 - "$OUT/kernels_$tag.csv" "$wall_ms" "$iterations" <<'PY' | tee -a "$summary"
import csv, re, sys
from collections import defaultdict
rows = list(csv.reader(open(sys.argv[1])))
wall_ms, iterations = float(sys.argv[2]), int(sys.argv[3])
head = next(r for r in rows if "Kernel Name" in r)
name_i, t_i = head.index("Kernel Name"), head.index("gpu__time_duration.sum")
total = defaultdict(float)
launches = defaultdict(int)
for r in rows:
    if len(r) <= t_i or not r[0].isdigit():
        continue
    name = re.sub(r"^void ", "", re.sub(r"\(.*", "", r[name_i]).strip())[:90]
    total[name] += float(r[t_i].replace(",", "")) / 1000.0  # ns -> us
    launches[name] += 1
s = sum(total.values())
renders = sum(n for k, n in launches.items() if "rasterizeBackward" in k) or 1
print(f"kernel time in the window: {s / 1000:.3f} ms over {renders} training renders (a step "
      f"renders one view, or two when it adds a labelled one) = {s / 1000 / renders:.3f} ms per "
      f"render; the whole training's wall time: {wall_ms / iterations:.3f} ms per iteration "
      f"(process, setup included; 0 when PLAIN=0)")
print(f"{'kernel':90s} {'launches':>8s} {'total us':>10s} {'mean us':>8s} {'share':>6s}")
for name, t in sorted(total.items(), key=lambda x: -x[1]):
    print(f"{name:90s} {launches[name]:8d} {t:10.1f} {t / launches[name]:8.2f} {100 * t / s:5.1f}%")
PY
