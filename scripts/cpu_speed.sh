#!/usr/bin/env bash
# Steady-state CPU training speed: iterations per second from the difference of a 300- and a
# 600-iteration run (start-up and scene loading cancel), on the demo city at two image sizes,
# Net-1 (--drop none). Build first (cmake --build build).
#   bash scripts/cpu_speed.sh [OUT_DIR=/tmp/sadsplat-cpu-speed] [THREADS=all cores]
# BIN (env): the sadsplat binary to time (build/bin/sadsplat).
# PASSES (env, 1): how many times to time each size; with more than one, each pass prints its own
# rates and a last line per size gives the median of the passes' ratios (a single pass of either
# program moves by ~10 % on a 2-core cloud machine).
# OPENSPLAT_SRC (env): a checkout of OpenSplat's public source (github.com/pierotofy/OpenSplat).
# The script then builds it for the CPU (-DGPU_RUNTIME=CPU against Debian's LibTorch; its
# FetchContent dependencies replaced by Debian's libnanoflann-dev, libcxxopts-dev and
# nlohmann-json3-dev, which it installs when missing) into OUT_DIR/opensplat-build, and times it
# the same way on the same scene (written as a scene directory with a binary COLMAP model, the
# only kind OpenSplat reads), at full size from the first step (--num-downscales 0), in the same
# run, alternating with sadsplat. OpenSplat renders RGB only; sadsplat also renders 32 feature
# channels on the steps with a labelled view (every second one).
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-/tmp/sadsplat-cpu-speed}"
threads="${2:-}"
[ -n "$threads" ] && export OMP_NUM_THREADS="$threads"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
bin="${BIN:-build/bin/sadsplat}"

# The machine, with the vector units that decide how fast LibTorch's operators run (OpenSplat's
# CPU path) and which of sadsplat's tile loops run (AVX2 lanes, else SSE2 rows): ratios from
# machines with other units differ.
simd=$(grep -o -w 'avx2\|fma\|avx512f\|amx_tile' /proc/cpuinfo 2>/dev/null | sort -u | tr '\n' ' ')
echo "machine: $(nproc) cores, $(lscpu 2>/dev/null | sed -n 's/^Model name: *//p'), SIMD beyond SSE2: ${simd:-none}"

# OpenSplat, built once per OUT_DIR.
opensplat=""
if [ -n "${OPENSPLAT_SRC:-}" ]; then
  src="$(cd "$OPENSPLAT_SRC" && pwd)"
  opensplat="$out/opensplat-build/opensplat"
  if [ ! -x "$opensplat" ]; then
    missing=()
    for p in libnanoflann-dev libcxxopts-dev nlohmann-json3-dev; do
      dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
    done
    [ ${#missing[@]} -eq 0 ] || apt-get install -y -q "${missing[@]}" >/dev/null
    # Small CMake folders standing in for the three FetchContent downloads: each gives the
    # target name OpenSplat links against, over the header Debian installs in /usr/include.
    stand_ins="$out/opensplat-stand-ins"
    for pair in nlohmann_json:nlohmann_json::nlohmann_json nanoflann:nanoflann::nanoflann \
                cxxopts:cxxopts::cxxopts; do
      name=${pair%%:*}; target=${pair#*:}
      mkdir -p "$stand_ins/$name"
      printf 'cmake_minimum_required(VERSION 3.16)\nproject(%s_stand_in NONE)\nadd_library(%s_stand_in INTERFACE)\nadd_library(%s ALIAS %s_stand_in)\n' \
        "$name" "$name" "$target" "$name" > "$stand_ins/$name/CMakeLists.txt"
    done
    cmake -S "$src" -B "$out/opensplat-build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
      -DGPU_RUNTIME=CPU -DCMAKE_PREFIX_PATH=/usr/lib/x86_64-linux-gnu/cmake/Torch \
      -DFETCHCONTENT_FULLY_DISCONNECTED=ON \
      -DFETCHCONTENT_SOURCE_DIR_NLOHMANN_JSON="$stand_ins/nlohmann_json" \
      -DFETCHCONTENT_SOURCE_DIR_NANOFLANN="$stand_ins/nanoflann" \
      -DFETCHCONTENT_SOURCE_DIR_CXXOPTS="$stand_ins/cxxopts" > "$out/opensplat-configure.log" 2>&1 ||
      { tail -20 "$out/opensplat-configure.log"; exit 1; }
    cmake --build "$out/opensplat-build" --target opensplat > "$out/opensplat-build.log" 2>&1 ||
      { tail -20 "$out/opensplat-build.log"; exit 1; }
  fi
  # Only the checkout's own commit: a copy inside another repository has none.
  commit="(not a git checkout)"
  [ -e "$src/.git" ] && commit=$(git -C "$src" describe --always --tags 2>/dev/null)
  echo "OpenSplat $commit, $(cat "$src/VERSION" 2>/dev/null)"
fi

seconds() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", b - a }'; }
now() { date +%s.%N; }

for size in 160x90 320x180; do
  w=${size%x*}; h=${size#*x}
  cache="$out/city_${size}.cache"
  [ -f "$cache" ] || "$bin" synth --kind city --seed 0 --width "$w" --height "$h" --cache "$cache" >/dev/null
  if [ -n "$opensplat" ] && [ ! -d "$out/city_${size}" ]; then
    "$bin" synth --kind city --seed 0 --width "$w" --height "$h" --out "$out/city_${size}" \
      --colmap-binary >/dev/null
  fi
  declare -A t o
  ratios=()
  for pass in $(seq "${PASSES:-1}"); do
    for n in 300 600; do
      rm -rf "$out/run_${size}_$n"
      t[$n]=$("$bin" train "$cache" --out "$out/run_${size}_$n" --iterations "$n" --drop none 2>&1 |
              tr '\r' '\n' | grep -o 'trained in [0-9.]*' | grep -o '[0-9.]*$')
      if [ -n "$opensplat" ]; then
        start=$(now)
        "$opensplat" "$out/city_${size}" --cpu -n "$n" --num-downscales 0 \
          -o "$out/opensplat_${size}_$n.ply" > "$out/opensplat_${size}_$n.log" 2>&1
        o[$n]=$(seconds "$start" "$(now)")
      fi
    done
    awk -v a="${t[300]}" -v b="${t[600]}" -v s="$size" -v th="${OMP_NUM_THREADS:-all}" \
      'BEGIN { printf "%s, threads %s: sadsplat 300 it %.1f s, 600 it %.1f s -> %.2f it/s steady\n", s, th, a, b, 300 / (b - a) }'
    if [ -n "$opensplat" ]; then
      awk -v a="${o[300]}" -v b="${o[600]}" -v s="$size" -v sa="${t[300]}" -v sb="${t[600]}" \
        'BEGIN { printf "%s: OpenSplat 300 it %.1f s, 600 it %.1f s -> %.2f it/s steady; sadsplat / OpenSplat %.2fx\n", s, a, b, 300 / (b - a), (b - a) / (sb - sa) }'
      ratios+=("$(awk -v a="${o[300]}" -v b="${o[600]}" -v sa="${t[300]}" -v sb="${t[600]}" \
                  'BEGIN { printf "%.4f", (b - a) / (sb - sa) }')")
    fi
  done
  if [ ${#ratios[@]} -gt 1 ]; then
    printf '%s\n' "${ratios[@]}" | sort -g | awk -v s="$size" \
      '{ r[NR] = $1 } END { m = NR % 2 ? r[(NR + 1) / 2] : (r[NR / 2] + r[NR / 2 + 1]) / 2;
         printf "%s: median sadsplat / OpenSplat over %d passes %.2fx (%.2f .. %.2f)\n", s, NR, m, r[1], r[NR] }'
  fi
done
