#!/usr/bin/env bash
# Run ON THE GPU MACHINE from the repository root: sadsplat against gsplat in one run of this script.
# Needs .deps/debs (scripts/gpu/fetch_deps.sh), .deps/gsplat (gsplat's source with Debian's
# glm headers) and .deps/fused-ssim (scripts/gsplat_reference/README.md) carried along.
#   [LIMIT=590] [GSPLAT_RUNS="ref"] bash scripts/gpu/gsplat_side_by_side.sh [bench] [SCENE ...]
# Builds sadsplat (build-gpu/) and gsplat (JIT, /tmp/gsplat-ext) side by side, then
#   bench   sadsplat_bench_rasterizer --device cuda and scripts/gsplat_reference/
#           bench_rasterizer_gsplat.py, alternating, two passes each (take the best of the two);
#   SCENE   (city_0, port_1, ...) trainings at 800x450, 7000 iterations, one at a time:
#           sadsplat Net-1 (--drop none, no pseudo-labels), sadsplat full (pseudo-labels +
#           --drop full), and the gsplat reference of Net-1 (GSPLAT_RUNS: ref = with fused-ssim's
#           CUDA SSIM, as gsplat's trainer; torchssim = SSIM composed of torch convolutions;
#           nossim = SSIM weight 0, a lower bound). LIKE_FOR_LIKE=1
#           adds sadsplat Net-1 with max_screen_radius 100000: no screen-size pruning, as
#           gsplat's default strategy, and densify_until 3500, the reference's refine_stop_iter
#           (the Gaussian counts then match).
# No run starts when fewer than its expected seconds are left before LIMIT. $OUT gets
# side_by_side.txt (the tables) and side_by_side.tgz (logs, metrics JSON).
set -uo pipefail
source "$(dirname "$0")/lib.sh"
start=$(date +%s)
limit="${LIMIT:-590}"
out="$OUT"
work=/tmp/side-by-side
rm -rf "$work"; mkdir -p "$work/logs"
summary="$out/side_by_side.txt"
left() { echo $(( limit - ($(date +%s) - start) )); }
py="${PYTHON:-python3}"

echo "== $(date -u +%F) sadsplat vs gsplat, $(nvidia-smi --query-gpu=name --format=csv,noheader | head -1)" | tee "$summary"
gpu_build > "$work/logs/build_sadsplat.log" 2>&1 &
sadsplat_build=$!
# gsplat: the JIT build of its CUDA extension with the channel counts used here (3 = RGB,
# 32 = a chunk of features, 35 = RGB + 32 features in one call).
export TORCH_EXTENSIONS_DIR=/tmp/gsplat-ext BUILD_2DGS=0 BUILD_3DGUT=0 BUILD_ADAM=0 BUILD_RELOC=0 \
  BUILD_LOSSES=0 NUM_CHANNELS="3,32,35" TORCH_CUDA_ARCH_LIST=9.0 MAX_JOBS=12
rm -rf /tmp/gsplat-src && cp -r .deps/gsplat /tmp/gsplat-src
export PYTHONPATH=/tmp/gsplat-src
"$py" -c "import rich" 2>/dev/null || {
  # gsplat's build helper only prints through rich.console.Console: a stand-in when it is missing.
  mkdir -p /tmp/pyshim/rich
  printf 'class Console:\n    def print(self, *a, **k): print(*a)\n    def status(self, *a, **k):\n        import contextlib; return contextlib.nullcontext()\n' > /tmp/pyshim/rich/console.py
  touch /tmp/pyshim/rich/__init__.py
  export PYTHONPATH=/tmp/gsplat-src:/tmp/pyshim
}
# A gsplat extension built by an earlier run (.deps/gsplat-prebuilt/*.so, same flags) saves the
# ~3 minutes of the JIT build: gsplat imports `gsplat.csrc` first, so a small module of that name
# loads it.
prebuilt=$(ls .deps/gsplat-prebuilt/*.so 2>/dev/null | head -1)
if [ -n "$prebuilt" ]; then
  so=$(basename "$prebuilt")
  cp "$prebuilt" /tmp/gsplat-src/gsplat/
  cat > /tmp/gsplat-src/gsplat/csrc.py <<EOF
import importlib.util as _util, os as _os
import torch as _torch  # noqa: F401 (the extension links against it)
_spec = _util.spec_from_file_location("${so%%.*}", _os.path.join(_os.path.dirname(__file__), "$so"))
_module = _util.module_from_spec(_spec)
_spec.loader.exec_module(_module)
globals().update({k: getattr(_module, k) for k in dir(_module) if not k.startswith("__")})
EOF
fi
gs_start=$(date +%s)
(cd /tmp/gsplat-src && "$py" -c "import gsplat, torch; from gsplat.cuda._backend import _C; print('gsplat', gsplat.__version__, 'torch', torch.__version__, 'ext', _C is not None)") \
  > "$work/logs/build_gsplat.log" 2>&1
gs_ok=$?
smoke_done=0
echo "gsplat build: rc $gs_ok, $(( $(date +%s) - gs_start )) s; $(tail -1 "$work/logs/build_gsplat.log")" | tee -a "$summary"
[ -z "$prebuilt" ] && find /tmp/gsplat-ext -name '*.so' -exec cp {} "$out/" \;
wait $sadsplat_build || { tail -30 "$work/logs/build_sadsplat.log"; }
bin=build-gpu/bin/sadsplat
echo "builds done at $(( $(date +%s) - start )) s" | tee -a "$summary"

args=("$@")
if [ "${args[0]:-}" = bench ]; then
  args=("${args[@]:1}")
  for pass in 1 2; do
    build-gpu/bin/sadsplat_bench_rasterizer --device cuda > "$work/logs/bench_sadsplat_$pass.txt" 2>&1
    if [ $gs_ok = 0 ]; then
      "$py" scripts/gsplat_reference/bench_rasterizer_gsplat.py > "$work/logs/bench_gsplat_$pass.txt" 2>&1
      "$py" scripts/gsplat_reference/bench_rasterizer_gsplat.py --packed > "$work/logs/bench_gsplat_packed_$pass.txt" 2>&1
    fi
  done
  for f in "$work"/logs/bench_*[12].txt; do echo "-- $(basename "$f")"; cat "$f"; done | tee -a "$summary"
fi

train_sadsplat() {  # NAME CACHE ARGS...
  local name=$1 cache=$2; shift 2
  local run="$work/run_$name"
  "$bin" train "$cache" --device cuda --out "$run" "$@" > "$work/logs/train_$name.log" 2>&1 &&
    "$bin" eval "$run" > "$work/metrics_$name.json" 2>> "$work/logs/train_$name.log"
}
for scene in "${args[@]}"; do
  [ "$(left)" -gt 100 ] || { echo "no time left for $scene" | tee -a "$summary"; break; }
  cache=$(scene_cache "$scene") || break
  [ "$(left)" -gt 75 ] && train_sadsplat "${scene}_net1" "$cache" --drop none
  if [ "${LIKE_FOR_LIKE:-0}" = 1 ] && [ "$(left)" -gt 90 ]; then
    # Net-1 without the screen-size pruning, as gsplat's default strategy (refine_scale2d_stop_iter 0),
    # densifying for half the iterations as the reference does (refine_stop_iter).
    echo '{"max_screen_radius": 100000, "densify_until": 3500}' > "$work/no_screen_pruning.json"
    train_sadsplat "${scene}_net1_nosr" "$cache" --drop none --config "$work/no_screen_pruning.json"
  fi
  if [ $gs_ok = 0 ] && [ $smoke_done = 0 ]; then
    # 1400 iterations: densification (until 700) and the evaluation run once, in seconds.
    smoke_done=1
    "$py" scripts/gsplat_reference/train_gsplat.py "$cache" --iterations 1400 \
      > "$work/logs/gsplat_smoke.log" 2>&1 || gs_ok=1
    echo "gsplat reference smoke run (1400 iterations): $(tail -1 "$work/logs/gsplat_smoke.log")" | tee -a "$summary"
  fi
  if [ $gs_ok = 0 ]; then
    for variant in ${GSPLAT_RUNS:-ref}; do
      [ "$(left)" -gt 110 ] || break
      ssim=(--ssim-weight 0.2 --ssim fused)
      [ "$variant" = torchssim ] && ssim=(--ssim-weight 0.2 --ssim torch)
      [ "$variant" = nossim ] && ssim=(--ssim-weight 0)
      timeout $(( $(left) - 5 )) "$py" scripts/gsplat_reference/train_gsplat.py "$cache" "${ssim[@]}" \
        --json "$work/gsplat_${scene}_$variant.json" > "$work/logs/gsplat_${scene}_$variant.log" 2>&1
    done
  fi
  if [ "$(left)" -gt 100 ]; then
    pl=$(pl_cache "$cache") && train_sadsplat "${scene}_full" "$pl" --drop full
  fi
done

"$py" - "$work" "$@" <<'PY' | tee -a "$summary"
import glob, json, os, sys
work = sys.argv[1]
def load(p):
    try:
        return json.load(open(p))
    except Exception:
        return None
rows = []
for scene in [a for a in sys.argv[2:] if a != "bench"]:
    n1 = load(f"{work}/metrics_{scene}_net1.json")
    fu = load(f"{work}/metrics_{scene}_full.json")
    nosr = load(f"{work}/metrics_{scene}_net1_nosr.json")
    for name, m in (("sadsplat Net-1", n1), ("sadsplat Net-1, no screen-size pruning", nosr),
                    ("sadsplat full", fu)):
        if m:
            rows.append((scene, name, m["train_seconds"], m["num_gaussians"], 100 * m["miou"], m["psnr"]))
    for p in sorted(glob.glob(f"{work}/gsplat_{scene}_*.json")):
        g = load(p)
        if g:
            tag = os.path.basename(p)[len(f"gsplat_{scene}_"):-5]
            rows.append((scene, f"gsplat reference ({tag})", g["train_seconds"], g["num_gaussians"], 100 * g["miou"], g["psnr"]))
print("| scene | trainer | train s | Gaussians | mIoU % | PSNR dB |")
print("|---|---|---|---|---|---|")
for r in rows:
    print("| %s | %s | %.1f | %d | %.2f | %.2f |" % r)
PY
tar czf "$out/side_by_side.tgz" -C "$work" logs $(cd "$work" && ls *.json 2>/dev/null)
echo "total $(( $(date +%s) - start )) s" | tee -a "$summary"
