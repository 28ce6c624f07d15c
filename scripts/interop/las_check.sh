#!/usr/bin/env bash
# A run's LAS exports read by a reader nobody on this project wrote (loaders.gl's LAS loader,
# laz-rs): the point count and the ASPRS class histogram must equal what `sadsplat info` reports.
#   bash scripts/interop/las_check.sh RUN OUT_DIR
# Writes OUT_DIR/gaussians.las (model.ply) and OUT_DIR/semantic.las (model_semantic.ply, when the
# run has one); prints a PASS/FAIL line for each and exits 1 on any FAIL. Needs node, npm and the
# npm registry (the reader goes to .deps/splat-tools, git-ignored). Not part of CI.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
run=$(readlink -f "$1")
out=$(mkdir -p "$2" && cd "$2" && pwd)
cli=${SADSPLAT_CLI:-$root/build/bin/sadsplat}
tools=$root/.deps/splat-tools
source "$root/scripts/interop/las_reader.sh"
failed=0
check() {  # input model, output las
  "$cli" convert "$1" "$2" >/dev/null
  local ours theirs
  ours=$("$cli" info "$2" | python3 -c '
import re, sys, json
text = sys.stdin.read()
points = int(re.search(r"^points: (\d+)", text, re.M).group(1))
hist = {m[0]: int(m[1]) for m in re.findall(r" (\d+) \([^)]*\):(\d+)", text)}
print(json.dumps({"points": points, "histogram": hist}, sort_keys=True))')
  theirs=$(cd "$tools" && node read_las_with_loadersgl.mjs "$2" | python3 -c '
import sys, json
d = json.loads(sys.stdin.read())
assert d["version"] == "1.4" and d["pointsFormatId"] == 7, d
print(json.dumps({"points": d["points"], "histogram": d["histogram"]}, sort_keys=True))')
  if [ "$ours" = "$theirs" ]; then
    echo "PASS $(basename "$2"): $ours"
  else
    echo "FAIL $(basename "$2"): sadsplat info $ours, loaders.gl $theirs"
    failed=1
  fi
}
check "$run/model.ply" "$out/gaussians.las"
[ -f "$run/model_semantic.ply" ] && check "$run/model_semantic.ply" "$out/semantic.las"
exit $failed
