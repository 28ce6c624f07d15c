#!/usr/bin/env bash
# ON THE GPU MACHINE from the repository root: the experiment tables, one named table per mode.
# Builds build-gpu/ if missing (scripts/gpu/lib.sh); scenes are synth caches at 800x450 made once.
#
#   bash scripts/gpu/experiments.sh one KIND_SEED [ITERATIONS=7000] [train args...]
#       one training + eval (TAG=name tells apart runs of one scene with different args)
#   bash scripts/gpu/experiments.sh profile [ITERATIONS=7000] [KIND_SEED ...]
#       where the training time goes: RUNS (full_plain full_profile none_profile) one at a time;
#       PL=1 trains the full runs on the scene with pseudo-labels; CONFIG=json goes to every run
#   bash scripts/gpu/experiments.sh runs KIND_SEED [JOBS=2] [DEADLINE_S=540] [RUN ...]
#       the drop / pseudo-label runs of one scene, JOBS at once (timings are then not clean)
#   bash scripts/gpu/experiments.sh table TABLE [JOBS=4] [DEADLINE_S=540]
#       the trainings of a benchmark table, resuming across calls (below)
#   bash scripts/gpu/experiments.sh scene SCENE JOBS DEADLINE_S 'NAME:train flags' ...
#       trainings + eval of any scene (a cache or directory, e.g. a real survey imported with
#       `sadsplat import`; or KIND_SEED for a synth scene, KIND_SEED_pl with pseudo-labels), JOBS
#       at once; ITERATIONS (7000); ORTHO=1 also scores the class orthophoto (eval --ortho, synth
#       scenes; and as the blend through the Gaussians: orthoblend_*.json), THREED=1 the per-class cloud in 3D (eval --3d, synth scenes); ORTHO_SURFACE="1 2" the orthophoto
#       of the Gaussians on the surface (eval --ortho --on-surface M: ortho_sM_*.json);
#       LABELLED=auto synth scenes with synth --labelled auto (the views pick-views advises);
#       ORTHO_RAISED="0.33" the class map with the raised-class check (eval --ortho --raised-check
#       F: ortho_rF_*.json); ORTHO_VARIANTS="TAG:eval flags;TAG:eval flags" the class map
#       with any other `eval --ortho` flags (ortho_vTAG_*.json); KEEP_RUNS=1
#       packs the run directories (no .ply / .pcd) into $OUT/runs_<scene>.tar.* (15 MiB parts);
#       $OUT gets
#       scene_<name>.txt and scene_<name>.tgz (metrics, logs); a training
#       stopped at the deadline is evaluated from its checkpoint (partial_<name>.json; the
#       summary says at which iteration it stopped). The deadline counts from the call's start
#       (lib.sh's CALL_START), a fresh machine's build (~100-140 s) and scene making included:
#       caches are made one at a time on the machine (lib.sh; city_0 with its pseudo-labels
#       ~30 s on an H100 machine; several made at once took 150-300 s, 2026-11-26) — give the
#       deadline room for them and for the evaluation after it (~50 s below the call's limit),
#       or carry a cache made elsewhere
#
# RUN names (runs): none_nopl none_pl full_p1_nopl full_p{0,0.5,1,1.5,2}_pl semantic_p1_pl
#   structure_p1_pl (suffix _pl: on the scene with pseudo-labels; _nopl: without); infixes set
#   training keys: _lambdaX lambda_l0, _lpX lambda_pseudo, _decgt pseudo_labels_train_decoder false,
#   _recN recovery_iterations, _cutX recovery_prune, _refssim fused_ssim false, _gthX
#   densify_grad_threshold, _radX max_screen_radius (e.g. none_rad100000_nopl: no screen-size
#   pruning, as gsplat's default strategy). PL_ARGS: extra `sadsplat pseudo-labels` arguments.
#
# TABLE (table): a run counts as done when the repository holds
# docs/experiments/TABLE/<kind>_<seed>/<config>_t<training seed>/metrics.json; $OUT gets
# table_TABLE.tgz (the new metrics.json files in that layout, train logs) and table_TABLE.txt:
#   tar xzf table_TABLE.tgz -C docs/experiments/TABLE && sadsplat table docs/experiments/TABLE \
#     --out docs/experiments/TABLE/README.md
#   defaults   3 seed-0 scenes x none (Net-1) and full (Net-4: pseudo-labels, --drop full) under
#              the current defaults x training seeds 0-2 (the README's default numbers)
#   ablation   9 scenes (city/country/port x seeds 0-2) x none (Net-1), drop (Net-2), pl (Net-3),
#              full (Net-4) x training seeds 0-2 (measured 2026-11-24/25: the paper's drop rule,
#              today --drop-rule paper, densifying for half the iterations)
#   pbase      3 seed-0 scenes x full with P_base 0 / 0.5 / 1 / 1.5 / 2 x training seeds 0-2
#   l0schedule 3 seed-0 scenes x full with the L0 weight off until N (_fromN), rising over M
#              (_rampM), weight X (_lambdaX)
#   growth     3 seed-0 scenes x Net-1 grown to fewer Gaussians (none_gradX: densify threshold X)
#   late       3 seed-0 scenes x Net-1, full, and late pruning (L0 force and drop events from 3500,
#              1000 recovery iterations) at L0 strength 3 and 4
#   recovery   3 seed-0 scenes x Net-1, full, and the default drop followed by 1000 recovery
#              iterations, alone and after removing 30 % / 50 % of the least contributing
#              Gaussians at the recovery's start (rp0.3, rp0.5)
#   A configuration full_<parts> takes any of pX (P_base), lambdaX, fromN, rampM, impG
#   (--l0-importance G), recN (--recovery N), sX (--l0-strength X), rpX (--recovery-prune X).
#   Env SCENES, CONFIGS, SEEDS restrict the lists; MIN_RUN_S (30): no run starts with less left;
#   SADSPLAT_BIN, DEVICE (cuda), WIDTH x HEIGHT (800 x 450), ITERATIONS (7000) change the setup
#   (e.g. a quick CPU check).
set -uo pipefail
source "$(dirname "$0")/lib.sh"
mode="${1:?usage: experiments.sh one|profile|runs|table ...}"; shift
[ -x "$SADSPLAT_BIN" ] || gpu_build || exit 1
bin=$SADSPLAT_BIN

mode_one() {
  local scene="$1" iterations="${2:-7000}"; shift $(( $# < 2 ? $# : 2 ))
  local cache; cache=$(scene_cache "$scene") || return 1
  local name="${scene}${TAG:+_$TAG}" run="/tmp/sadsplat-one/run_${scene}${TAG:+_$TAG}"
  rm -rf "$run"; mkdir -p /tmp/sadsplat-one
  "$bin" train "$cache" --device cuda --iterations "$iterations" --out "$run" "$@" > "$OUT/train_$name.log" 2>&1 ||
    { tail -5 "$OUT/train_$name.log"; return 1; }
  echo "drop events: $(tr '\r' '\n' < "$OUT/train_$name.log" | grep -c '^\[drop\]')"
  "$bin" eval "$run" > "$OUT/metrics_$name.json" && cp "$run/config.json" "$OUT/config_$name.json"
  metrics_line "$name" "$OUT/metrics_$name.json"
}

mode_profile() {
  local iterations="${1:-7000}"; shift $(( $# < 1 ? $# : 1 ))
  local scenes=("$@"); [ ${#scenes[@]} -gt 0 ] || scenes=(city_0)
  local summary="$OUT/summary.txt" scene run
  for scene in "${scenes[@]}"; do
    local cache pl=""; cache=$(scene_cache "$scene") || return 1
    [ "${PL:-0}" = 1 ] && { pl=$(pl_cache "$cache") || return 1; }
    for run in ${RUNS:-full_plain full_profile none_profile}; do
      local drop=${run%_*} flags=()
      [ "${run#*_}" = profile ] && flags=(--profile)
      [ -n "${CONFIG:-}" ] && flags+=(--config "$CONFIG")
      local scene_file="$cache"; [ -n "$pl" ] && [ "$drop" = full ] && scene_file="$pl"
      local dir="/tmp/sadsplat-profile/${scene}_$run"; rm -rf "$dir"; mkdir -p /tmp/sadsplat-profile
      local start; start=$(date +%s%N)
      "$bin" train "$scene_file" --device cuda --iterations "$iterations" --drop "$drop" --out "$dir" \
        "${flags[@]}" > "$OUT/train_${scene}_$run.log" 2>&1
      echo "$scene $run: wall $(( ($(date +%s%N) - start) / 1000000 )) ms (process), $(train_summary "$OUT/train_${scene}_$run.log")" | tee -a "$summary"
      [ -f "$dir/profile.md" ] && cp "$dir/profile.md" "$OUT/profile_${scene}_$run.md"
      [ "${run#*_}" = plain ] && "$bin" eval "$dir" > "$OUT/metrics_${scene}_$run.json" 2>/dev/null
    done
  done
  nvidia-smi --query-gpu=name,memory.used,memory.total --format=csv >> "$summary" 2>&1 || true
}

# One run of mode `runs`: its flags from its name.
runs_train_one() {
  local name="$1" cache="$2" pl="$3" work="$4" res="$5"
  local args=() scene="$cache" keys=()
  case "$name" in *_pl) scene="$pl" ;; esac
  case "$name" in *_lambda*) local l0=${name#*_lambda}; keys+=("\"lambda_l0\": ${l0%%_*}") ;; esac
  case "$name" in *_lp*) local lp=${name#*_lp}; keys+=("\"lambda_pseudo\": ${lp%%_*}") ;; esac
  case "$name" in *_decgt*) keys+=("\"pseudo_labels_train_decoder\": false") ;; esac
  case "$name" in *_gth*) local gth=${name#*_gth}; keys+=("\"densify_grad_threshold\": ${gth%%_*}") ;; esac
  case "$name" in *_refssim*) keys+=("\"fused_ssim\": false") ;; esac
  case "$name" in *_rad*) local rad=${name#*_rad}; keys+=("\"max_screen_radius\": ${rad%%_*}") ;; esac
  case "$name" in *_rec*) local rec=${name#*_rec}; keys+=("\"recovery_iterations\": ${rec%%_*}") ;; esac
  case "$name" in *_cut*) local cut=${name#*_cut}; keys+=("\"recovery_prune\": ${cut%%_*}") ;; esac
  if [ ${#keys[@]} -gt 0 ]; then
    (IFS=,; echo "{${keys[*]}}") > "$work/config_$name.json"; args=(--config "$work/config_$name.json")
  fi
  case "$name" in
    none_*) args+=(--drop none) ;;
    full_p*) local p=${name#full_p}; p=${p%%_*}; args+=(--drop full --p-base "$p") ;;
    semantic_p1_*) args+=(--drop semantic --p-base 1) ;;
    structure_p1_*) args+=(--drop structure --p-base 1) ;;
    *) echo "unknown run $name"; return 1 ;;
  esac
  run_until_deadline "$bin" train "$scene" --device cuda --iterations 7000 --out "$work/run_$name" "${args[@]}" \
    > "$res/train_$name.log" 2>&1 || { echo "$name: train stopped (rc $?)"; return 1; }
  "$bin" eval "$work/run_$name" > "$res/metrics_$name.json" 2> "$res/eval_$name.log"
  cp "$work/run_$name/config.json" "$res/config_$name.json"
}

mode_runs() {
  local scene="$1" jobs="${2:-2}"; deadline_start "${3:-540}"; shift $(( $# < 3 ? $# : 3 ))
  local runs=("$@")
  [ ${#runs[@]} -gt 0 ] || runs=(none_nopl full_p1_pl none_pl full_p1_nopl structure_p1_pl semantic_p1_pl
                                  full_p0_pl full_p2_pl full_p0.5_pl full_p1.5_pl)
  local tag="${scene}${PL_TAG:-}" work="/tmp/sadsplat-exp/${scene}${PL_TAG:-}"
  local res="$work/results"; mkdir -p "$res"
  local cache pl; cache=$(scene_cache "$scene") || return 1
  # shellcheck disable=SC2086
  pl=$(pl_cache "$cache" "$bin" ${PL_ARGS:-}) || return 1
  local name
  for name in "${runs[@]}"; do
    # A run needs about RUN_SECONDS (2 at once on an H100: ~160 s); don't start one that can't end.
    [ "$(seconds_left)" -gt "${RUN_SECONDS:-170}" ] || { echo "$name: not started (deadline)"; continue; }
    while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n; done
    runs_train_one "$name" "$cache" "$pl" "$work" "$res" &
  done
  wait
  local summary="$OUT/summary_$tag.txt" f
  echo "$scene 800x450, 7000 iterations, $jobs at once; pseudo-labels args: '${PL_ARGS:-}'" > "$summary"
  for f in "$res"/metrics_*.json; do [ -f "$f" ] && metrics_line "$(basename "${f%.json}" | cut -c9-)" "$f"; done >> "$summary"
  for f in "$res"/train_*.log; do tr '\r' '\n' < "$f" | grep '^\[drop\]\|semantic supervision' | tail -3 | sed "s|^|$(basename "$f"): |"; done >> "$summary"
  tar -czf "$OUT/results_$tag.tar.gz" -C "$work" results
  cat "$summary"
}

# One training of mode `table`: table_run_one SCENE CONFIG SEED.
table_run_one() {
  local scene=$1 config=$2 seed=$3
  local name="${config}_t$seed" cache flags=(--drop none)
  cache=$(scene_cache "$scene" "$size") || return 1
  case "$config" in
    none) ;;
    none_grad*)
      local json="$work/${config}.json"
      echo "{\"densify_grad_threshold\": ${config#none_grad}}" > "$json"
      flags+=(--config "$json") ;;
    drop) flags=(--drop full) ;;
    pl) cache=$(pl_cache "$cache") ;;
    full|full_*)
      cache=$(pl_cache "$cache"); flags=(--drop full)
      local token
      for token in ${config//_/ }; do
        case "$token" in
          full) ;;
          p[0-9]*) flags+=(--p-base "${token#p}") ;;
          lambda*) flags+=(--lambda-l0 "${token#lambda}") ;;
          from*) flags+=(--lambda-l0-from "${token#from}") ;;
          ramp*) flags+=(--lambda-l0-ramp "${token#ramp}") ;;
          imp*) flags+=(--l0-importance "${token#imp}") ;;
          rec[0-9]*) flags+=(--recovery "${token#rec}") ;;
          s[0-9]*) flags+=(--l0-strength "${token#s}") ;;
          rp[0-9]*) flags+=(--recovery-prune "${token#rp}") ;;
          *) echo "unknown part $token of configuration $config"; return 1 ;;
        esac
      done ;;
    *) echo "unknown configuration $config"; return 1 ;;
  esac
  local run="$work/runs/$scene/$name" dest="$new/$scene/$name"
  rm -rf "$run"; mkdir -p "$(dirname "$run")" "$dest"
  local t0; t0=$(date +%s)
  if run_until_deadline "$bin" train "$cache" --device "$device" --iterations "$iterations" \
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

mode_table() {
  table="${1:?usage: experiments.sh table defaults|ablation|pbase|l0schedule|growth|late|recovery [JOBS] [DEADLINE_S]}"
  local parallel="${2:-4}"; deadline_start "${3:-540}"
  device="${DEVICE:-cuda}"; size="${WIDTH:-800}x${HEIGHT:-450}"; iterations="${ITERATIONS:-7000}"
  local scenes configs
  case "$table" in
    defaults) scenes=(city_0 country_0 port_0); configs=(none full) ;;
    ablation) scenes=(city_0 country_0 port_0 city_1 country_1 port_1 city_2 country_2 port_2)
              configs=(none full drop pl) ;;
    pbase)    scenes=(city_0 country_0 port_0); configs=(full_p1 full_p0 full_p2 full_p0.5 full_p1.5) ;;
    l0schedule) scenes=(city_0 country_0 port_0)
              configs=(full_from3500 full_from3500_lambda0.4 full_from2000_ramp1500) ;;
    growth)   scenes=(city_0 country_0 port_0); configs=(none_grad0.0005 none_grad0.001 none_grad0.002) ;;
    late)     scenes=(city_0 country_0 port_0)
              configs=(none full full_from3500_rec1000_s3 full_from3500_rec1000_s4) ;;
    recovery) scenes=(city_0 country_0 port_0)
              configs=(none full full_rec1000 full_rec1000_rp0.3 full_rec1000_rp0.5) ;;
    *) echo "unknown table $table (defaults, ablation, pbase, l0schedule, growth, late or recovery)"; return 2 ;;
  esac
  [ -n "${SCENES:-}" ] && read -r -a scenes <<< "$SCENES"
  [ -n "${CONFIGS:-}" ] && read -r -a configs <<< "$CONFIGS"
  local seeds=(0 1 2); [ -n "${SEEDS:-}" ] && read -r -a seeds <<< "$SEEDS"
  local done_dir="docs/experiments/$table"
  work=/tmp/sadsplat-table/$table; new="$work/new"; log="$OUT/table_$table.txt"
  rm -rf "$new"; mkdir -p "$new"   # only this call's runs go back
  echo "== $(date -u +%F) table $table: ${#scenes[@]} scenes x ${#configs[@]} configurations x ${#seeds[@]} seeds, $parallel at once, $device $size, $iterations iterations" | tee -a "$log"
  local pending=0 scene config seed item
  for scene in "${scenes[@]}"; do
    local todo=()
    for config in "${configs[@]}"; do
      for seed in "${seeds[@]}"; do
        [ -f "$done_dir/$scene/${config}_t$seed/metrics.json" ] || todo+=("$config:$seed")
      done
    done
    [ ${#todo[@]} -eq 0 ] && continue
    # The scene (and its pseudo-labels) once, before the runs that share it start.
    scene_cache "$scene" "$size" > /dev/null && pl_cache "$(scene_cache "$scene" "$size")" > /dev/null ||
      { echo "$scene: preparation stopped" | tee -a "$log"; break; }
    for item in "${todo[@]}"; do
      # A run started too late is killed at the deadline and wasted.
      [ "$(seconds_left)" -le "${MIN_RUN_S:-30}" ] && break 2
      while [ "$(jobs -rp | wc -l)" -ge "$parallel" ]; do wait -n; done
      table_run_one "$scene" "${item%%:*}" "${item##*:}" &
      pending=$((pending + 1))
    done
  done
  wait
  echo "started $pending runs, $(find "$new" -name metrics.json | wc -l) finished" | tee -a "$log"
  tar czf "$OUT/table_$table.tgz" -C "$new" .
}

mode_scene() {
  local scene="$1" jobs="$2"; deadline_start "$3"; shift 3
  local cache="$scene"
  if [ ! -e "$scene" ]; then
    case "$scene" in
      *_pl) cache=$(scene_cache "${scene%_pl}") && cache=$(pl_cache "$cache") || return 1 ;;
      *) cache=$(scene_cache "$scene") || return 1 ;;
    esac
  fi
  local tag; tag=$(basename "${scene%.cache}")
  [ "${CAPTURE:-orbit}" = orbit ] || tag="${tag}_$CAPTURE"
  [ -z "${LABELLED:-}" ] || tag="${tag}_l${LABELLED//,/-}"
  local work="/tmp/sadsplat-scene/$tag"; rm -rf "$work"; mkdir -p "$work/results"
  local spec
  for spec in "$@"; do
    local name="${spec%%:*}" flags="${spec#*:}"
    [ "$(seconds_left)" -gt 20 ] || { echo "$name: not started (deadline)"; continue; }
    while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n; done
    (
      # shellcheck disable=SC2086
      run_until_deadline "$bin" train "$cache" --device cuda --iterations "${ITERATIONS:-7000}" \
        --out "$work/run_$name" $flags > "$work/results/train_$name.log" 2>&1 &&
        "$bin" eval "$work/run_$name" > "$work/results/metrics_$name.json" 2> "$work/results/eval_$name.log" &&
        { [ "${ORTHO:-0}" = 0 ] || "$bin" eval "$work/run_$name" --ortho \
            > "$work/results/ortho_$name.json" 2>> "$work/results/eval_$name.log"; } &&
        { [ "${ORTHO:-0}" = 0 ] || "$bin" eval "$work/run_$name" --ortho --height blend \
            --min-views 0 > "$work/results/orthoblend_$name.json" 2>> "$work/results/eval_$name.log"; } &&
        { [ "${THREED:-0}" = 0 ] || "$bin" eval "$work/run_$name" --3d \
            > "$work/results/3d_$name.json" 2>> "$work/results/eval_$name.log"; } &&
        for m in ${ORTHO_SURFACE:-}; do
          "$bin" eval "$work/run_$name" --ortho --on-surface "$m" \
            > "$work/results/ortho_s${m}_$name.json" 2>> "$work/results/eval_$name.log" || exit 1
        done &&
        for r in ${ORTHO_RAISED:-}; do
          "$bin" eval "$work/run_$name" --ortho --raised-check "$r" \
            > "$work/results/ortho_r${r}_$name.json" 2>> "$work/results/eval_$name.log" || exit 1
        done &&
        IFS=';' read -ra variants <<< "${ORTHO_VARIANTS:-}" &&
        for v in "${variants[@]}"; do
          # shellcheck disable=SC2086
          "$bin" eval "$work/run_$name" --ortho ${v#*:} \
            > "$work/results/ortho_v${v%%:*}_$name.json" 2>> "$work/results/eval_$name.log" || exit 1
        done || {
        echo "$name: stopped (rc $?)"
        # A training stopped at the deadline leaves its checkpoint: evaluate the model as it was
        # (metrics.json says at which iteration), so that a run too long for the call still says
        # where it got to.
        if [ -f "$work/run_$name/checkpoint.bin" ] && [ ! -s "$work/results/metrics_$name.json" ]; then
          timeout 60 "$bin" eval "$work/run_$name" > "$work/results/partial_$name.json" \
            2>> "$work/results/eval_$name.log"
        fi
      }
    ) &
  done
  wait
  if [ "${KEEP_RUNS:-0}" = 1 ]; then
    # shellcheck disable=SC2046  # the run directories' names, relative to $work
    tar cf - -C "$work" --exclude='*.pcd' --exclude='*.ply' $(cd "$work" && ls -d run_*) |
      split -b 15M - "$OUT/runs_$tag.tar."
  fi
  local summary="$OUT/scene_$tag.txt" f
  echo "== $(date -u +%F) $scene, ${ITERATIONS:-7000} iterations, $jobs at once, $(nvidia-smi --query-gpu=name --format=csv,noheader | head -1)" > "$summary"
  for spec in "$@"; do
    local name="${spec%%:*}"
    f="$work/results/metrics_$name.json"
    [ -s "$f" ] && metrics_line "$name" "$f" >> "$summary"
    f="$work/results/partial_$name.json"
    if [ -s "$f" ]; then
      local stopped_at
      stopped_at=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["iterations"])' "$f")
      metrics_line "$name (stopped at iteration $stopped_at)" "$f" >> "$summary"
    fi
    f="$work/results/ortho_$name.json"
    [ -s "$f" ] && python3 -c 'import json,sys; m=json.load(open(sys.argv[1])); print("    ortho (%s m): mIoU %.2f  OA %.2f  uncovered %.1f %%  area error %s" % (m["gsd"], 100*m["miou"], 100*m["oacc"], 100*m["uncovered_share"], " ".join("%s %+.0f%%" % (k, 100*v["relative_error"]) for k, v in m["area"].items() if v["relative_error"] is not None)))' "$f" >> "$summary"
    for f in "$work/results"/ortho_r*_"$name".json; do
      [ -s "$f" ] && python3 -c 'import json,sys; m=json.load(open(sys.argv[1])); b=m["area"].get("building"); print("    ortho raised check %s: mIoU %.2f  building %s  lowered %.1f %%  near ground %.0f %%  raised %s" % (m["raised_check"], 100*m["miou"], "%+.0f %%" % (100*b["relative_error"]) if b else "-", 100*m.get("raised_lowered_share", 0), 100*m.get("near_ground_share", 0), ",".join(m.get("raised_classes", []))))' "$f" >> "$summary"
    done
    for f in "$work/results"/ortho_s*_"$name".json; do
      [ -s "$f" ] && python3 -c 'import json,sys; m=json.load(open(sys.argv[1])); d=m["dsm"]["per_class"]; print("    ortho on surface %s: mIoU %.2f  uncovered %.1f %%  building %+.0f %%  DSM %.2f m (roofs %.2f, road %.2f)  map objects F1 %.2f" % (m["on_surface_m"], 100*m["miou"], 100*m["uncovered_share"], 100*m["area"]["building"]["relative_error"], m["dsm"]["rmse_m"], d["building"]["rmse_m"], d["road"]["rmse_m"], m["objects"]["f1"]))' "$f" >> "$summary"
    done
    f="$work/results/3d_$name.json"
    [ -s "$f" ] && python3 -c 'import json,sys; m=json.load(open(sys.argv[1])); print("    3d: point mIoU %.2f (weighted %.2f)  OA %.2f  opaque %d of %d: median %.2f m, p90 %.2f m, within 0.5 m %.1f %%, beyond 1 m %.1f %%  completeness %.1f %% (%s)" % (100*m["point_miou"], 100*m["weighted_miou"], 100*m["point_oacc"], m["opaque"], m["gaussians"], m["distance_median_m"], m["distance_p90_m"], 100*m["share_within_0.5_m"], 100*m["share_beyond_1.0_m"], 100*m["completeness_all"], " ".join("%s %.0f" % (k, 100*v) for k, v in m["completeness"].items() if v is not None)))' "$f" >> "$summary"
    f="$work/results/train_$name.log"
    if [ -f "$f" ]; then
      echo "    flags: ${spec#*:}; $(train_summary "$f"); drops: $(tr '\r' '\n' < "$f" | grep -c '^\[drop\]')" >> "$summary"
    else
      echo "    flags: ${spec#*:}; not started" >> "$summary"
    fi
  done
  tar -czf "$OUT/scene_$tag.tgz" -C "$work" results
  cat "$summary"
}

case "$mode" in
  scene) mode_scene "$@" ;;
  one) mode_one "$@" ;;
  profile) mode_profile "$@" ;;
  runs) mode_runs "$@" ;;
  table) mode_table "$@" ;;
  *) echo "unknown mode $mode (one, profile, runs, table or scene)"; exit 2 ;;
esac
