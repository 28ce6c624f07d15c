#!/usr/bin/env bash
# Run ON THE GPU MACHINE from the repository root: the trainings of one benchmark table, several
# at once, resuming across calls. A run counts as done when the repository already holds its
# docs/experiments/TABLE/<kind>_<seed>/<config>_t<training seed>/metrics.json (bring the results of
# earlier calls back, commit them, and the next call goes on with the rest).
#   bash scripts/gpu/table_runs.sh TABLE [JOBS=4] [DEADLINE_S=540]
# TABLE:
#   ablation   the 9 benchmark scenes (city/country/port x seeds 0-2) x none (Net-1: no drop, no
#              pseudo-labels), drop (Net-2: full drop), pl (Net-3: pseudo-labels), full (Net-4:
#              both) x training seeds 0-2
#   pbase      the 3 seed-0 scenes x full drop with pseudo-labels, P_base 0 / 0.5 / 1 / 1.5 / 2
#              (configurations full_p0 ... full_p2) x training seeds 0-2; full_p1 is the ablation's
#              `full` (same flags: P_base 1 is the default), its runs copied into the pbase folder
#   l0schedule the 3 seed-0 scenes x full drop with pseudo-labels and the L0 weight off until
#              iteration N (_fromN), rising over M iterations (_rampM), weight X (_lambdaX)
#   growth     the 3 seed-0 scenes x Net-1 grown to fewer Gaussians (none_gradX, below)
# none_gradX: Net-1 with densify_grad_threshold X (fewer Gaussians grown; the frontier without a
# drop). A configuration full_<parts> takes any of the parts pX (P_base), lambdaX, fromN, rampM, impG
# (--l0-importance G: the L0 term weighted towards the Gaussians that contribute least).
# Env: SCENES, CONFIGS, SEEDS restrict the lists; MIN_RUN_S (30): no run starts with less left; BIN (build-gpu/bin/sadsplat), DEVICE (cuda),
# WIDTH x HEIGHT (800 x 450), ITERATIONS (7000) change the setup (e.g. a quick CPU check).
# No run starts after DEADLINE_S and every run stops at it. $OUT gets table_TABLE.tgz (the new
# metrics.json files in the layout above, plus train logs) and table_TABLE.txt (what ran, how long):
#   tar xzf table_TABLE.tgz -C docs/experiments/TABLE && sadsplat table docs/experiments/TABLE \
#     --out docs/experiments/TABLE/README.md
set -uo pipefail
table="${1:?usage: table_runs.sh ablation|pbase|l0schedule|growth [JOBS] [DEADLINE_S]}"
parallel="${2:-4}"; deadline="${3:-540}"
start=$(date +%s)
out="${OUT:-/tmp/sadsplat-gpu-out}"
mkdir -p "$out"
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1
export PYTORCH_CUDA_ALLOC_CONF=expandable_segments:True
bin="${BIN:-build-gpu/bin/sadsplat}"
device="${DEVICE:-cuda}"; width="${WIDTH:-800}"; height="${HEIGHT:-450}"; iterations="${ITERATIONS:-7000}"
if [ "$bin" = build-gpu/bin/sadsplat ]; then
  [ -x "$bin" ] || bash scripts/gpu/build.sh > /tmp/sadsplat-build.log 2>&1 || { tail -30 /tmp/sadsplat-build.log; exit 1; }
  export LD_LIBRARY_PATH="/tmp/sadsplat-deps/usr/lib/x86_64-linux-gnu:${LD_LIBRARY_PATH:-}"
fi
case "$table" in
  ablation) scenes=(city_0 country_0 port_0 city_1 country_1 port_1 city_2 country_2 port_2)
            configs=(none full drop pl) ;;
  pbase)    scenes=(city_0 country_0 port_0)
            configs=(full_p1 full_p0 full_p2 full_p0.5 full_p1.5) ;;
  l0schedule) scenes=(city_0 country_0 port_0)
            configs=(full_from3500 full_from3500_lambda0.4 full_from2000_ramp1500) ;;
  growth)   scenes=(city_0 country_0 port_0)
            configs=(none_grad0.0005 none_grad0.001 none_grad0.002) ;;
  *) echo "unknown table $table (ablation, pbase, l0schedule or growth)"; exit 2 ;;
esac
[ -n "${SCENES:-}" ] && read -r -a scenes <<< "$SCENES"
[ -n "${CONFIGS:-}" ] && read -r -a configs <<< "$CONFIGS"
seeds=(0 1 2); [ -n "${SEEDS:-}" ] && read -r -a seeds <<< "$SEEDS"
done_dir="docs/experiments/$table"
work=/tmp/sadsplat-table/$table
new="$work/new"
rm -rf "$new"; mkdir -p "$new"   # only this call's runs go back
log="$out/table_$table.txt"
echo "== $(date -u +%F) table $table: ${#scenes[@]} scenes x ${#configs[@]} configurations x ${#seeds[@]} seeds, $parallel at once, $device ${width}x$height, $iterations iterations" | tee -a "$log"

left() { echo $(( deadline - ($(date +%s) - start) )); }

# The scene cache (and, for configurations with pseudo-labels, its pseudo-labelled copy).
prepare() {
  local scene=$1 with_pl=$2 kind=${1%_*} seed=${1##*_}
  local dir="$work/scenes/$scene"; mkdir -p "$dir"
  [ -f "$dir/scene.cache" ] || timeout "$(left)" "$bin" synth --kind "$kind" --seed "$seed" \
    --width "$width" --height "$height" --cache "$dir/scene.cache" > "$dir/synth.log" 2>&1 || return 1
  if [ "$with_pl" = 1 ] && [ ! -f "$dir/scene_pl.cache" ]; then
    timeout "$(left)" "$bin" pseudo-labels "$dir/scene.cache" --out "$dir/scene_pl.cache" \
      > "$dir/pseudo_labels.log" 2>&1 || return 1
  fi
}

# One training + evaluation: run_one SCENE CONFIG SEED.
run_one() {
  local scene=$1 config=$2 seed=$3
  local dir="$work/scenes/$scene" name="${config}_t$seed"
  local cache="$dir/scene.cache" flags=(--drop none)
  case "$config" in
    none) ;;
    none_grad*)
      # Net-1 grown to fewer Gaussians: a higher densification gradient threshold.
      local json="$work/${config}.json"
      echo "{\"densify_grad_threshold\": ${config#none_grad}}" > "$json"
      flags+=(--config "$json") ;;
    drop) flags=(--drop full) ;;
    pl) cache="$dir/scene_pl.cache" ;;
    full|full_*)
      cache="$dir/scene_pl.cache"; flags=(--drop full)
      local token
      for token in ${config//_/ }; do
        case "$token" in
          full) ;;
          p[0-9]*) flags+=(--p-base "${token#p}") ;;
          lambda*) flags+=(--lambda-l0 "${token#lambda}") ;;
          from*) flags+=(--lambda-l0-from "${token#from}") ;;
          ramp*) flags+=(--lambda-l0-ramp "${token#ramp}") ;;
          imp*) flags+=(--l0-importance "${token#imp}") ;;
          *) echo "unknown part $token of configuration $config"; return 1 ;;
        esac
      done ;;
    *) echo "unknown configuration $config"; return 1 ;;
  esac
  local run="$work/runs/$scene/$name" dest="$new/$scene/$name"
  rm -rf "$run"; mkdir -p "$(dirname "$run")" "$dest"
  local t0; t0=$(date +%s)
  if timeout "$(left)" "$bin" train "$cache" --device "$device" --iterations "$iterations" \
       --seed "$seed" --out "$run" "${flags[@]}" > "$dest/train.log" 2>&1 &&
     "$bin" eval "$run" > "$run/eval.out" 2> "$dest/eval.log"; then
    cp "$run/metrics.json" "$dest/metrics.json"
    echo "$scene $name: $(( $(date +%s) - t0 )) s" >> "$log"
  else
    echo "$scene $name: stopped after $(( $(date +%s) - t0 )) s" >> "$log"
    rm -f "$dest/metrics.json"
  fi
  # Keep the log small: the progress lines are carriage-return updates.
  tr '\r' '\n' < "$dest/train.log" | grep -v '^\[[0-9]*/[0-9]*\] loss' | tail -40 > "$dest/train.log.tail"
  mv "$dest/train.log.tail" "$dest/train.log"
}

pending=0
for scene in "${scenes[@]}"; do
  needs_pl=0; todo=()
  for config in "${configs[@]}"; do
    for seed in "${seeds[@]}"; do
      [ -f "$done_dir/$scene/${config}_t$seed/metrics.json" ] && continue
      todo+=("$config:$seed")
      case "$config" in none|none_*|drop) ;; *) needs_pl=1 ;; esac
    done
  done
  [ ${#todo[@]} -eq 0 ] && continue
  [ "$(left)" -le 30 ] && break
  prepare "$scene" "$needs_pl" || { echo "$scene: preparation stopped" | tee -a "$log"; break; }
  for item in "${todo[@]}"; do
    # A run started too late is killed at the deadline and wasted: MIN_RUN_S is what one run
    # needs at the chosen parallelism (~270-330 s with 6 at once on an H100).
    [ "$(left)" -le "${MIN_RUN_S:-30}" ] && break
    while [ "$(jobs -rp | wc -l)" -ge "$parallel" ]; do wait -n; done
    run_one "$scene" "${item%%:*}" "${item##*:}" &
    pending=$((pending + 1))
  done
done
wait
finished=$(find "$new" -name metrics.json | wc -l)
echo "started $pending runs, $finished finished, $(( $(date +%s) - start )) s" | tee -a "$log"
tar czf "$out/table_$table.tgz" -C "$new" .
