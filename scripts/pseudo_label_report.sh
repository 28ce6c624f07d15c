#!/usr/bin/env bash
# Pseudo-label quality of the built-in backend on the nine benchmark scenes (city / country /
# port, seeds 0-2) at 800x450: synth -> pseudo-labels --report, one line per scene and filter k.
# Usage: scripts/pseudo_label_report.sh [OUT_DIR] [extra pseudo-labels args...]
set -euo pipefail
OUT=${1:-out/pseudo_label_report}
shift || true
BIN=${SADSPLAT_BIN:-build/bin/sadsplat}
mkdir -p "$OUT"
for kind in city country port; do
  for seed in 0 1 2; do
    cache="$OUT/${kind}_${seed}.cache"
    [ -f "$cache" ] || "$BIN" synth --kind "$kind" --seed "$seed" --width 800 --height 450 --cache "$cache" >/dev/null
    for k in 1 0.5 0; do
      rep="$OUT/${kind}_${seed}_k${k}"
      "$BIN" pseudo-labels "$cache" --out "$OUT/${kind}_${seed}_k${k}.cache" --filter-k "$k" --report "$rep" "$@" \
        > "$rep.log"
      echo "$kind $seed k=$k: $(grep '^pseudo-labels on' "$rep/report.txt")"
      echo "$kind $seed k=$k: $(grep '^worst kept class' "$rep/report.txt" || echo 'worst kept class: none')"
      rm -f "$OUT/${kind}_${seed}_k${k}.cache"
    done
  done
done
