#!/usr/bin/env bash
# ON THE GPU MACHINE from the repository root: several `experiments.sh scene` tables at once (one
# per scene and capture), every run scored by eval, eval --ortho and eval --3d; the results packed
# into two archives so that a table of many scenes comes back as few files.
#
#   RUNS='SCENE|CAPTURE|NAME:train flags|NAME:train flags;SCENE|CAPTURE|...' \
#     [DEADLINE=470] bash scripts/gpu/scenes_at_once.sh
#
# e.g. RUNS='city_1_pl|orbit|full:--drop full;city_1|grid-oblique|none:--drop none'
# SCENE as experiments.sh takes it (KIND_SEED, KIND_SEED_pl with pseudo-labels); CAPTURE orbit |
# grid | grid-oblique; each item trains its runs at once, all items together. $OUT then holds only
# results.tgz (<scene>[_capture]/results/*.json), logs.tgz (the train / eval logs) and the
# summaries scene_*.txt; python3 scripts/analysis/map_table.py reads the unpacked results.
set -u
CALL_START=$(date +%s)
export CALL_START
# shellcheck source=scripts/gpu/lib.sh
source "$(dirname "$0")/lib.sh"
[ -x "$SADSPLAT_BIN" ] || gpu_build || { tail -30 "$OUT"/gpu_*.log; exit 1; }
echo "build ready at $(( $(date +%s) - CALL_START )) s"
IFS=';' read -ra items <<< "${RUNS:?RUNS='SCENE|CAPTURE|NAME:flags;...'}"
for item in "${items[@]}"; do
  IFS='|' read -ra fields <<< "$item"
  scene=${fields[0]} capture=${fields[1]} specs=("${fields[@]:2}")
  CAPTURE=$capture THREED=1 ORTHO=1 bash "$(dirname "$0")/experiments.sh" scene "$scene" \
    "${#specs[@]}" "${DEADLINE:-470}" "${specs[@]}" > "$OUT/exp_${scene}_$capture.log" 2>&1 &
  sleep 2  # the scene caches are made one at a time: start them in the order given
done
wait
echo "all done at $(( $(date +%s) - CALL_START )) s"
work=/tmp/sadsplat-scene
cp "$OUT"/exp_*.log "$work"/
(cd "$work" && tar czf /tmp/results.tgz ./*/results/*.json && tar czf /tmp/logs.tgz ./*/results/*.log ./exp_*.log)
cat "$OUT"/scene_*.txt
keep=$(mktemp -d)
mv /tmp/results.tgz /tmp/logs.tgz "$OUT"/scene_*.txt "$keep"/
rm -rf "${OUT:?}"/* && mv "$keep"/* "$OUT"/ && rmdir "$keep"
