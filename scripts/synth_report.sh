#!/usr/bin/env bash
# Generates the nine benchmark scenes (city/country/port x seeds 0..2) and prints generation time,
# effective-pixel share and class shares for each. Usage: scripts/synth_report.sh [demo|full] [OUT]
set -euo pipefail
preset="${1:-demo}"
out="${2:-out/benchmark}"
bin="$(dirname "$0")/../build/bin/sadsplat"
mkdir -p "$out"
for kind in city country port; do
  for seed in 0 1 2; do
    start=$(date +%s.%N)
    "$bin" synth --kind "$kind" --seed "$seed" --preset "$preset" --out "$out/${kind}_${seed}" --preview \
      | sed -n 's/^/  /p'
    echo "$kind seed $seed: $(echo "$(date +%s.%N) - $start" | bc) s wall (incl. writing)"
  done
done
