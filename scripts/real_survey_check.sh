#!/usr/bin/env bash
# A real-photo check (not CI: it needs photos you bring). From a folder of drone photos to an
# evaluated model, every stage timed; the numbers go to OUT/summary.txt.
#   bash scripts/real_survey_check.sh PHOTOS OUT [--device cuda] [--iterations 7000]
#        [--annotations LABELME_DIR_OR_COCO --classes classes.json] [--scale 0.5]
# Example (the public Brighton Beach set, docs/measurements/real_brighton/README.md):
#   bash scripts/real_survey_check.sh .deps/real/brighton out/brighton --iterations 2000 \
#     --annotations docs/measurements/real_brighton/labelme \
#     --classes docs/measurements/real_brighton/labelme/classes.json --scale 0.25
# Trains Net-1 (--drop none) and, with annotations, the full method with pseudo-labels; without
# annotations `--drop structure` (no labels needed).
set -euo pipefail
photos="${1:?usage: real_survey_check.sh PHOTOS OUT [options]}"; out="${2:?OUT}"; shift 2
device=cpu; iterations=7000; annotations=""; classes=""; scale=0.5; max_size=1600
while [ $# -gt 0 ]; do
  case "$1" in
    --device) device="$2"; shift 2 ;;
    --iterations) iterations="$2"; shift 2 ;;
    --annotations) annotations="$2"; shift 2 ;;
    --classes) classes="$2"; shift 2 ;;
    --scale) scale="$2"; shift 2 ;;
    --max-image-size) max_size="$2"; shift 2 ;;
    *) echo "unknown option $1"; exit 2 ;;
  esac
done
bin="${SADSPLAT:-build/bin/sadsplat}"
mkdir -p "$out"
summary="$out/summary.txt"
echo "== $(date -u +%F) $photos, $(nproc) cores, $device, $iterations iterations" | tee "$summary"
timed() {  # NAME COMMAND...
  local name=$1; shift
  local t0; t0=$(date +%s.%N)
  "$@" > "$out/$name.log" 2>&1 || { echo "$name failed: $(tail -1 "$out/$name.log")" | tee -a "$summary"; exit 1; }
  echo "$name: $(python3 -c "import sys; print(round(float(sys.argv[1]) - float(sys.argv[2]), 1))" "$(date +%s.%N)" "$t0") s" | tee -a "$summary"
}
[ -d "$out/scene/sparse" ] || timed sfm "$bin" sfm "$photos" --out "$out/scene" --max-image-size "$max_size"
grep '^sfm: registered\|^sfm: not registered' "$out/sfm.log" | tee -a "$summary" || true
import_args=()
if [ -n "$annotations" ]; then
  cp "$classes" "$out/scene/classes.json"
  import_args=(--annotations "$annotations")
fi
timed import "$bin" import "$out/scene" --out "$out/scene.cache" --scale "$scale" "${import_args[@]}"
head -1 "$out/import.log" | tee -a "$summary"
timed net1 "$bin" train "$out/scene.cache" --out "$out/net1" --device "$device" \
  --iterations "$iterations" --drop none
if [ -n "$annotations" ]; then
  timed pseudo_labels "$bin" pseudo-labels "$out/scene.cache" --out "$out/scene_pl.cache"
  timed drop "$bin" train "$out/scene_pl.cache" --out "$out/drop" --device "$device" \
    --iterations "$iterations" --drop full
else
  timed drop "$bin" train "$out/scene.cache" --out "$out/drop" --device "$device" \
    --iterations "$iterations" --drop structure
fi
for run in net1 drop; do
  "$bin" eval "$out/$run" > "$out/metrics_$run.json"
  python3 - "$out/metrics_$run.json" "$run" <<'PY' | tee -a "$summary"
import json, sys
m = json.load(open(sys.argv[1]))
iou = {k: round(100 * v, 1) for k, v in m["per_class_iou"].items() if v is not None}
print("%s: %d Gaussians, held-out PSNR %.2f dB, SSIM %.3f, mIoU %s %s" % (
    sys.argv[2], m["num_gaussians"], m["psnr"], m["ssim"],
    "none (%s)" % m["miou_note"] if m["miou"] is None else "%.2f %%" % (100 * m["miou"]), iou))
PY
done
