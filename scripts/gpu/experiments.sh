#!/usr/bin/env bash
# Run ON THE GPU MACHINE: the drop and pseudo-label experiments of one benchmark scene, several
# trainings at once on the one GPU (timings from such runs are not clean single-run times).
#   bash scripts/gpu/experiments.sh KIND SEED [JOBS=2] [DEADLINE_S=540] [RUN ...]
# Builds build-gpu/ if missing, generates the scene at 800x450 as a cache, runs
# `sadsplat pseudo-labels` on it (report kept), then trains + evaluates each RUN (default: all
# below, most important first) with 7000 iterations. No run starts after DEADLINE_S seconds and
# every run is stopped at it, so a run on the GPU machine returns in time with what finished.
# Runs:  none_nopl  none_pl  full_p1_nopl  full_p{0,0.5,1,1.5,2}_pl  semantic_p1_pl  structure_p1_pl
#        (suffix _pl: trained on the cache with pseudo-labels; _nopl: without); an infix _lambdaX
#        (e.g. full_p1_lambda0.4_pl) sets lambda_l0 = X, _lpX lambda_pseudo = X, and _decgt
#        pseudo_labels_train_decoder = false (e.g. none_decgt_pl), _recN recovery_iterations = N
#        and _cutX recovery_prune = X (e.g. full_p1_lambda0.2_rec1000_cut0.3_pl), _refssim
#        fused_ssim = false, _gthX densify_grad_threshold = X (fewer Gaussians without a drop),
#        _radX max_screen_radius = X (e.g. none_rad100000_nopl: no screen-size pruning, as gsplat's
#        default strategy).
# $OUT gets results_KIND_SEED.tar.gz (metrics, configs, logs, pseudo-label report) and
# summary_KIND_SEED.txt. Env PL_ARGS: extra `sadsplat pseudo-labels` arguments, with PL_TAG (a
# name suffix for the work dir and the outputs, so that two label variants can run side by side).
set -uo pipefail
# 2 at once by default. A training used ~30 GB in an earlier version (5 or 3 at once ran out of
# memory on an 80 GB H100); the current code peaks near 2 GB per process
# (docs/measurements/h100_screen_radius/), so JOBS=6 fits; the GPU's time is shared either way.
export PYTORCH_CUDA_ALLOC_CONF=expandable_segments:True
kind="$1"; seed="$2"; jobs="${3:-2}"; deadline="${4:-540}"; shift $(( $# < 4 ? $# : 4 ))
runs=("$@")
[ ${#runs[@]} -gt 0 ] || runs=(none_nopl full_p1_pl none_pl full_p1_nopl structure_p1_pl semantic_p1_pl
                                full_p0_pl full_p2_pl full_p0.5_pl full_p1.5_pl)
start=$(date +%s)
out="${OUT:-/tmp/sadsplat-gpu-out}"
mkdir -p "$out"
[ -x build-gpu/bin/sadsplat ] || bash scripts/gpu/build.sh > /tmp/sadsplat-build.log 2>&1 || { tail -30 /tmp/sadsplat-build.log; exit 1; }
export LD_LIBRARY_PATH="/tmp/sadsplat-deps/usr/lib/x86_64-linux-gnu:${LD_LIBRARY_PATH:-}"
bin=build-gpu/bin/sadsplat
tag="${kind}_${seed}${PL_TAG:-}"
work=/tmp/sadsplat-exp/$tag
res=$work/results
mkdir -p "$res"
cache="$work/scene.cache"
[ -f "$cache" ] || "$bin" synth --kind "$kind" --seed "$seed" --width 800 --height 450 --cache "$cache" > "$res/synth.log" 2>&1
[ -f "$work/scene_pl.cache" ] || /usr/bin/time -v "$bin" pseudo-labels "$cache" --out "$work/scene_pl.cache" \
  --report "$res/pseudo_report" ${PL_ARGS:-} > "$res/pseudo_labels.log" 2>&1
echo "prepared in $(( $(date +%s) - start )) s"

train_one() {
  local name="$1" left="$2"
  local args=() scene="$cache"
  case "$name" in *_pl) scene="$work/scene_pl.cache" ;; esac
  local keys=()
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
  timeout "$left" "$bin" train "$scene" --device cuda --iterations 7000 --out "$work/run_$name" "${args[@]}" \
    > "$res/train_$name.log" 2>&1 || { echo "$name: train stopped (rc $?)"; return 1; }
  "$bin" eval "$work/run_$name" > "$res/metrics_$name.json" 2> "$res/eval_$name.log"
  cp "$work/run_$name/config.json" "$res/config_$name.json"
}

for name in "${runs[@]}"; do
  now=$(( $(date +%s) - start ))
  [ "$now" -lt "$deadline" ] || { echo "$name: not started (deadline)"; continue; }
  while [ "$(jobs -rp | wc -l)" -ge "$jobs" ]; do wait -n; done
  now=$(( $(date +%s) - start ))
  # A run needs about RUN_SECONDS (2 at once on an H100: ~160 s); don't start one that can't end.
  [ $(( now + ${RUN_SECONDS:-170} )) -lt "$deadline" ] || { echo "$name: not started (deadline)"; continue; }
  train_one "$name" $(( deadline - now )) &
done
wait

python3 - "$res" "$kind" "$seed" "${PL_ARGS:-}" > "$out/summary_$tag.txt" <<'PY'
import glob, json, os, sys
res, kind, seed, pl_args = sys.argv[1:]
print(f"{kind} seed {seed}, 800x450, 7000 iterations, H100, several runs at once; pseudo-labels args: '{pl_args}'")
rows = []
for f in sorted(glob.glob(os.path.join(res, "metrics_*.json"))):
    name = os.path.basename(f)[8:-5]
    try:
        m = json.load(open(f))
    except Exception as e:
        print(name, "unreadable", e); continue
    rows.append((name, m))
    print("%-16s mIoU %6.2f  mAcc %6.2f  OA %6.2f  PSNR %6.2f  SSIM %.3f  gaussians %8d  train %5.0f s  render %.2f ms" % (
        name, 100*m['miou'], 100*m['macc'], 100*m['oacc'], m['psnr'], m['ssim'], m['num_gaussians'], m['train_seconds'],
        m.get('render_ms', float('nan'))))
rep = os.path.join(res, "pseudo_report", "report.txt")
if os.path.exists(rep):
    print(open(rep).read())
PY
grep -h 'builtin:\|Elapsed\|Maximum resident' "$res/pseudo_labels.log" >> "$out/summary_$tag.txt" || true
for f in "$res"/train_*.log; do tr '\r' '\n' < "$f" | grep '^\[drop\]\|semantic supervision' | tail -3 | sed "s|^|$(basename "$f"): |"; done \
  >> "$out/summary_$tag.txt"
tar -czf "$out/results_$tag.tar.gz" -C "$work" results
cat "$out/summary_$tag.txt"
echo "total $(( $(date +%s) - start )) s"
