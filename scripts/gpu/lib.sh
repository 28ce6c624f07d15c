# Shared blocks of the GPU scripts; sourced, never run. ON THE GPU MACHINE (Ubuntu 24.04,
# LibTorch 2.11 + CUDA 13, no PCL/OpenCV/VTK), from the repository root, with .deps/debs carried
# along (scripts/gpu/fetch_deps.sh fills it on Debian).
#
#   gpu_build [SRC_DIR]          build SRC_DIR (default .) into SRC_DIR/build-gpu with CUDA; logs
#                                in $OUT/gpu_*.log; incremental when build-gpu/ exists;
#                                GPU_BUILD_TARGET (env, e.g. sadsplat) builds that target only
#   gpu_baseline TARBALL         unpack a baseline source tarball into /tmp/ab-base and build it
#                                with this tree's lib.sh (sets BASE_BIN_DIR)
#   scene_cache KIND_SEED [WxH] [BIN]
#                                print the path of the synth scene cache (CAPTURE=grid-oblique
#                                for synth's drone-mission capture; made once per kind,
#                                seed and size under /tmp/sadsplat-scenes; KIND_SEED e.g. city_0,
#                                or city-xl / city-xxl for the large presets; LABELLED=auto
#                                for synth's --labelled)
#   pl_cache CACHE [BIN] [ARGS]  print the path of CACHE with the built-in pseudo-labels (made once)
#   make_cache PATH LOG CMD...   run CMD (writing PATH.part) once per PATH, one maker per machine
#   deadline_start SECONDS       the deadline: SECONDS after the first script of this call sourced
#                                lib.sh (a fresh machine's build, ~100-140 s, counts), or after
#                                CALL_START (env, epoch seconds); seconds_left prints what is left
#   run_until_deadline CMD...    run CMD, killed at the deadline; returns its status
#   metrics_line NAME JSON       one line of a run's `sadsplat eval` metrics
# Variables: OUT (results folder, default /tmp/sadsplat-gpu-out), SADSPLAT_BIN (build-gpu/bin/sadsplat).

OUT="${OUT:-/tmp/sadsplat-gpu-out}"
mkdir -p "$OUT"
GPU_DEPS_PREFIX=/tmp/sadsplat-deps
SADSPLAT_BIN="${SADSPLAT_BIN:-$PWD/build-gpu/bin/sadsplat}"
SCENES_DIR=/tmp/sadsplat-scenes
# The unpacked Debian libraries (gpu_unpack_deps) on the search path of every script that sources
# this file, so a binary built earlier in the same call runs.
export LD_LIBRARY_PATH="$GPU_DEPS_PREFIX/usr/lib/x86_64-linux-gnu:${LD_LIBRARY_PATH:-}"
export PYTORCH_CUDA_ALLOC_CONF="${PYTORCH_CUDA_ALLOC_CONF:-expandable_segments:True}"
# NVLink multicast stays off, also in the ranks the launcher starts (they inherit this).
export NCCL_NVLS_ENABLE=0 TORCH_SYMM_MEM_DISABLE_MULTICAST=1 NVSHMEM_DISABLE_NVLS=1

# Debian's PCL & co., unpacked once per set of packages (two builds on one machine share it).
gpu_unpack_deps() {
  local stamp
  stamp=$(ls -l .deps/debs/ | md5sum | cut -d' ' -f1)
  if [ "$(cat "$GPU_DEPS_PREFIX/.unpacked" 2>/dev/null)" != "$stamp" ]; then
    rm -rf "$GPU_DEPS_PREFIX" && mkdir -p "$GPU_DEPS_PREFIX"
    local deb
    for deb in .deps/debs/*.deb; do dpkg -x "$deb" "$GPU_DEPS_PREFIX"; done
    echo "$stamp" > "$GPU_DEPS_PREFIX/.unpacked"
  fi
}

gpu_build() {
  local src="${1:-.}"
  (
    cd "$src" || exit 1
    # One build of a tree at a time: two scripts started together (e.g. two experiments.sh) both
    # build; unlocked, they raced in one build-gpu/ and a link failed (2026-11-27). The second
    # waits and finds the build up to date.
    mkdir -p build-gpu
    exec {build_lock}> build-gpu/.build.lock
    flock "$build_lock"
    gpu_unpack_deps
    local torch_cmake=/opt/torch/.venv/lib/python3.12/site-packages/torch/share/cmake
    [ -d "$torch_cmake" ] || torch_cmake=$(python3 -c 'import torch; print(torch.utils.cmake_prefix_path)')
    export PATH=/usr/local/cuda/bin:$PATH
    local generator=(-G "Unix Makefiles")
    command -v ninja >/dev/null && generator=(-G Ninja)
    {
      echo "== machine"; nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv || true
      nvcc --version | tail -2; g++ --version | head -1; cmake --version | head -1
    } > "$OUT/gpu_env.log" 2>&1
    # zlib (.spz): the machine's own when it has the headers, else the unpacked Debian package.
    local zlib_args=()
    [ -f /usr/include/zlib.h ] || zlib_args=(-DZLIB_ROOT="$GPU_DEPS_PREFIX/usr")
    local start; start=$(date +%s)
    cmake -S . -B build-gpu "${generator[@]}" -DCMAKE_BUILD_TYPE=Release \
      -DCMAKE_PREFIX_PATH="$torch_cmake" \
      -DSADSPLAT_PCL_ROOT="$GPU_DEPS_PREFIX" \
      -Dnlohmann_json_DIR="$GPU_DEPS_PREFIX/usr/share/cmake/nlohmann_json" \
      -DCLI11_DIR="$GPU_DEPS_PREFIX/usr/share/cmake/CLI11" \
      -DSADSPLAT_WITH_CUDA=ON -DSADSPLAT_WITH_OPENCV=OFF -DSADSPLAT_WITH_VTK=OFF \
      -DSADSPLAT_WITH_OPEN3D=OFF "${zlib_args[@]}" > "$OUT/gpu_configure${2:-}.log" 2>&1 &&
    cmake --build build-gpu -j "$(nproc)" ${GPU_BUILD_TARGET:+--target "$GPU_BUILD_TARGET"} \
      > "$OUT/gpu_build${2:-}.log" 2>&1
    local rc=$?
    echo "build of $src: rc $rc, $(( $(date +%s) - start )) s" | tee -a "$OUT/gpu_build${2:-}.log"
    [ $rc = 0 ] || tail -30 "$OUT/gpu_build${2:-}.log"
    exit $rc
  )
  return $?
}

# BASE is a source tarball of the baseline: git archive --format=tar REV | gzip > .deps/base_src.tgz
gpu_baseline() {
  local tarball="$1"
  rm -rf /tmp/ab-base && mkdir -p /tmp/ab-base && tar -xzf "$tarball" -C /tmp/ab-base || return 1
  ln -s "$PWD/.deps" /tmp/ab-base/.deps
  BASE_BIN_DIR=/tmp/ab-base/build-gpu/bin
  gpu_build /tmp/ab-base _base
}

# make_cache PATH LOG CMD...: runs CMD (which writes PATH.part) unless PATH exists, then renames
# PATH.part to PATH. Callers asking for one PATH side by side wait for the first (a lock per cache);
# and one cache is made at a time on the machine (scene or pseudo-labels, whichever caller): two
# pseudo-labelled scenes made at once took > 150 s on a 16-core H100 machine (2026-11-26), one
# alone ~30 s with its synth.
make_cache() {
  local path="$1" log="$2"; shift 2
  mkdir -p "$SCENES_DIR"
  local lock making rc=0
  exec {lock}> "$path.lock"; flock "$lock"
  if [ ! -f "$path" ]; then
    exec {making}> "$SCENES_DIR/.making.lock"; flock "$making"
    "$@" > "$log" 2>&1 && mv "$path.part" "$path" || rc=1
    exec {making}>&-
  fi
  exec {lock}>&-
  return $rc
}

scene_cache() {
  local scene="$1" size="${2:-800x450}" bin="${3:-$SADSPLAT_BIN}"
  # CAPTURE (orbit, the default | grid | grid-oblique): synth's --capture; its own cache name.
  local capture="${CAPTURE:-orbit}" suffix=""
  [ "$capture" = orbit ] || suffix="_$capture"
  local args
  if [[ $scene == city-xl || $scene == city-xxl ]]; then args=(--kind city --preset "$scene")
  else args=(--kind "${scene%_*}" --seed "${scene##*_}"); fi
  args+=(--capture "$capture")
  # LABELLED (e.g. auto): synth's --labelled; its own cache name.
  if [ -n "${LABELLED:-}" ]; then suffix="${suffix}_l${LABELLED//,/-}"; args+=(--labelled "$LABELLED"); fi
  local cache="$SCENES_DIR/${scene}_${size}$suffix.cache"
  make_cache "$cache" "$OUT/synth_${scene}_$size$suffix.log" "$bin" synth "${args[@]}" \
    --width "${size%x*}" --height "${size#*x}" --cache "$cache.part" ||
    { echo "synth $scene failed" >&2; return 1; }
  echo "$cache"
}

pl_cache() {
  local cache="$1" bin="${2:-$SADSPLAT_BIN}"; shift $(( $# < 2 ? $# : 2 ))
  local tag=""; [ $# -gt 0 ] && tag="_$(echo "$*" | md5sum | cut -c1-8)"
  local pl="${cache%.cache}_pl$tag.cache"
  make_cache "$pl" "$OUT/pseudo_labels_$(basename "${pl%.cache}").log" \
    "$bin" pseudo-labels "$cache" --out "$pl.part" "$@" ||
    { echo "pseudo-labels of $cache failed" >&2; return 1; }
  echo "$pl"
}

# The call's clock starts when lib.sh is first sourced (exported, so scripts started from this
# one share it): a deadline given as the call's limit minus a margin then holds even when the
# build came first (a deadline counted from after a 104 s build let two long trainings and their
# evaluation run past a 600 s call, 2026-11-27).
export CALL_START="${CALL_START:-$(date +%s)}"
deadline_start() { DEADLINE_AT=$(( CALL_START + $1 )); }
seconds_left() { echo $(( ${DEADLINE_AT:?deadline_start first} - $(date +%s) )); }
run_until_deadline() {
  local left; left=$(seconds_left)
  [ "$left" -gt 0 ] || return 124
  timeout "$left" "$@"
}

# The last "trained in X s" and "gaussians N" of a training log (progress lines end in \r).
train_summary() {
  echo "$(tr '\r' '\n' < "$1" | grep -o 'trained in [0-9.]* s' | tail -1) $(tr '\r' '\n' < "$1" | grep -o 'gaussians [0-9]*' | tail -1)"
}

metrics_line() {  # NAME METRICS_JSON
  python3 - "$@" <<'PY'
import json, sys
name, path = sys.argv[1:3]
try:
    m = json.load(open(path))
except Exception as e:
    print(name, "unreadable", e); sys.exit()
miou = "%6.2f" % (100 * m["miou"]) if m.get("miou") is not None else "  none"
covered = ("  covered %6.2f (%2.0f %%)" % (m["psnr_covered"], 100 * m["covered_fraction"])
           if m.get("psnr_covered") is not None else "")
large = m.get("floaters", {}).get("larger_than_10pct_extent")
print("%-24s mIoU %s  PSNR %6.2f%s  SSIM %.3f  gaussians %8d  large %s  train %5.1f s" % (
    name, miou, m["psnr"], covered, m["ssim"], m["num_gaussians"], large, m["train_seconds"]))
PY
}
