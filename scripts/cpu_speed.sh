#!/usr/bin/env bash
# Steady-state CPU training speed: iterations per second from the difference of a 300- and a
# 600-iteration run (start-up and scene loading cancel), on the demo city at two image sizes,
# Net-1 (--drop none). Build first (cmake --build build).
#   bash scripts/cpu_speed.sh [OUT_DIR=/tmp/sadsplat-cpu-speed] [THREADS=all cores]
set -euo pipefail
cd "$(dirname "$0")/.."
out="${1:-/tmp/sadsplat-cpu-speed}"
threads="${2:-}"
[ -n "$threads" ] && export OMP_NUM_THREADS="$threads"
mkdir -p "$out"
bin=build/bin/sadsplat
for size in 160x90 320x180; do
  w=${size%x*}; h=${size#*x}
  cache="$out/city_${size}.cache"
  [ -f "$cache" ] || "$bin" synth --kind city --seed 0 --width "$w" --height "$h" --cache "$cache" >/dev/null
  declare -A t
  for n in 300 600; do
    rm -rf "$out/run_${size}_$n"
    t[$n]=$("$bin" train "$cache" --out "$out/run_${size}_$n" --iterations "$n" --drop none 2>&1 |
            tr '\r' '\n' | grep -o 'trained in [0-9.]*' | grep -o '[0-9.]*$')
  done
  awk -v a="${t[300]}" -v b="${t[600]}" -v s="$size" -v th="${OMP_NUM_THREADS:-all}" \
    'BEGIN { printf "%s, threads %s: 300 it %.1f s, 600 it %.1f s -> %.2f it/s steady\n", s, th, a, b, 300 / (b - a) }'
done
