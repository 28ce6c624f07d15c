#!/usr/bin/env bash
# What removing floaters at the end of a training costs on the test views: takes a finished run,
# continues it by one iteration with --prune-floaters rules (and once without, the control), and
# evaluates each copy.
#   bash scripts/floater_experiment.sh RUN SCENE [SADSPLAT=build/bin/sadsplat]
# e.g. after `bash scripts/demo.sh`:  bash scripts/floater_experiment.sh out/demo/run out/demo/city_demo.cache
# Prints one line per variant: removed, mIoU, PSNR, SSIM, Gaussians, floater census.
set -euo pipefail
run=${1:?usage: floater_experiment.sh RUN SCENE [SADSPLAT]}
scene=${2:?usage: floater_experiment.sh RUN SCENE [SADSPLAT]}
bin=${3:-build/bin/sadsplat}
iterations=$(grep -o '"iterations": *[0-9]*' "$run/run.json" | grep -o '[0-9]*$')
summary() {  # NAME METRICS.JSON
  tr -d ' \n' < "$2" | grep -o '"miou":[0-9.]*\|"psnr":[0-9.]*\|"ssim":[0-9.]*\|"num_gaussians":[0-9]*\|"floaters":{[^}]*}' |
    tr '\n' ' ' | sed "s/^/$1: /"; echo
}
"$bin" eval "$run" > "$run.metrics.json" 2>/dev/null
summary "as trained" "$run.metrics.json"
# name min_views max_scale (fraction of the scene extent); "control" prunes nothing.
for variant in "control 0 0" "views2 2 0" "size10 0 0.1" "both_10 2 0.1" "both_5 2 0.05" "both_2 2 0.02"; do
  set -- $variant
  copy="$run.$1"; rm -rf "$copy"; cp -r "$run" "$copy"
  prune=true; [ "$1" = control ] && prune=false
  # One key per line (the trainer writes config.json pretty-printed): replace or add the four.
  sed -E -i '/"(prune_floaters|floater_min_views|floater_max_scale|checkpoint_interval)":/d' "$copy/config.json"
  sed -E -i "0,/\{/s//{\n  \"prune_floaters\": $prune, \"floater_min_views\": $2, \"floater_max_scale\": $3, \"checkpoint_interval\": 0,/" "$copy/config.json"
  removed=$("$bin" train "$scene" --config "$copy/config.json" --iterations $((iterations + 1)) \
      --resume --out "$copy" 2>&1 | tr '\r' '\n' | grep -o 'removed [0-9]* Gaussians seen\|removed [0-9]* Gaussians larger' | grep -o '[0-9]*' || echo 0)
  "$bin" eval "$copy" > "$copy.metrics.json" 2>/dev/null
  summary "$1 (min views $2, max scale $3 x extent; removed $removed)" "$copy.metrics.json"
done
