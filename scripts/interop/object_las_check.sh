#!/usr/bin/env bash
# `ortho --object-clouds`'s per-object LAS files read by a reader nobody on this project wrote
# (loaders.gl's LAS loader, laz-rs): each file's LAS version and point format, its point count
# against objects.csv's `gaussians`, one ASPRS class per file, and the object's map position
# (objects.csv's map_x / map_y) inside the file's bounds.
#   bash scripts/interop/object_las_check.sh RUN OUT_DIR [CLASSES=building]
# Runs `sadsplat ortho RUN --out OUT_DIR --vectors CLASSES --object-clouds`; prints one PASS / FAIL
# line and exits 1 on FAIL. Needs node, npm and the npm registry (the reader goes to
# .deps/splat-tools, git-ignored: scripts/interop/las_reader.sh). Not part of CI.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
run=$(readlink -f "$1")
out=$(mkdir -p "$2" && cd "$2" && pwd)
classes=${3:-building}
cli=${SADSPLAT_CLI:-$root/build/bin/sadsplat}
tools=$root/.deps/splat-tools
source "$root/scripts/interop/las_reader.sh"
"$cli" ortho "$run" --out "$out" --vectors "$classes" --object-clouds --object-min-opacity 0.05 \
  > "$out/ortho.log"
: > "$out/loaders.jsonl"
for f in "$out"/objects/*.las; do
  (cd "$tools" && node read_las_with_loadersgl.mjs "$f") | sed "s|^|$(basename "$f") |" \
    >> "$out/loaders.jsonl"
done
python3 - "$out" <<'PY'
import csv, json, sys
out = sys.argv[1]
rows = {r["las_file"]: r for r in csv.DictReader(open(out + "/objects/objects.csv")) if r["las_file"]}
ok, bad = 0, []
for line in open(out + "/loaders.jsonl"):
    name, data = line.split(" ", 1)
    d, r = json.loads(data), rows.get(name)
    (x0, y0, _), (x1, y1, _) = d["bounds"]
    good = (r is not None and d["version"] == "1.4" and d["pointsFormatId"] == 7
            and d["points"] == int(r["gaussians"]) and len(d["histogram"]) == 1
            and x0 - 1e-3 <= float(r["map_x"]) <= x1 + 1e-3
            and y0 - 1e-3 <= float(r["map_y"]) <= y1 + 1e-3)
    if good:
        ok += 1
    else:
        bad.append(name)
if bad or ok != len(rows):
    print("FAIL: %d of %d object LAS files as objects.csv says; not: %s" % (ok, len(rows), bad[:10]))
    sys.exit(1)
print("PASS: %d object LAS files read by loaders.gl (LAS 1.4, format 7) hold objects.csv's points,"
      " one class each, around its map position" % ok)
PY
