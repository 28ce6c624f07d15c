#!/usr/bin/env bash
# Reads sadsplat's web formats with tools nobody on this project wrote, and sadsplat with theirs:
#   bash scripts/interop/splat_interop_check.sh MODEL.ply OUT_DIR
# 1. sadsplat writes MODEL as .spz v3 and v4; Niantic's decoder (@spz-loader/core, asked for RDF)
#    and PlayCanvas' splat-transform decode them; every attribute is compared with MODEL within
#    SPZ's quantisation (compare_with_reference_readers.mjs).
# 2. splat-transform writes MODEL as .spz v4, .sog and .compressed.ply, and a plain .ply of its
#    decode (where 255 alphas are +inf); sadsplat reads each (`info`, `convert` to .ply) and the
#    counts are compared; the .spz's attributes as in 1.
# 3. sadsplat writes MODEL as .sog; splat-transform reads it with the same count.
# Prints one line per check and OUT_DIR/summary.txt; exit 1 if any check fails. Needs node, npm
# and the npm registry (the tools go to .deps/splat-tools, git-ignored). Not part of CI.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
model=$(readlink -f "$1")
out=$(mkdir -p "$2" && cd "$2" && pwd)
cli=${SADSPLAT_CLI:-$root/build/bin/sadsplat}
tools=$root/.deps/splat-tools
if [ ! -d "$tools/node_modules/@playcanvas/splat-transform" ]; then
  mkdir -p "$tools"
  (cd "$tools" && npm init -y >/dev/null && npm install --no-audit --no-fund \
     @playcanvas/splat-transform@2.7.1 @spz-loader/core@0.3.1 >/dev/null)
fi
cp "$root/scripts/interop/compare_with_reference_readers.mjs" "$tools/"
st() { (cd "$tools" && npx splat-transform -q -w "$@"); }
failed=0
report() { echo "$1" | tee -a "$out/summary.txt"; }
: > "$out/summary.txt"
report "model: $model ($("$cli" info "$model" | grep -m1 gaussians))"

"$cli" convert "$model" "$out/sadsplat_v3.spz"
"$cli" convert "$model" "$out/sadsplat_v4.spz" --spz-version 4
check() {  # name, kind, file
  local line
  if line=$(cd "$tools" && node compare_with_reference_readers.mjs "$model" "$2" "$3" 2>&1); then
    report "PASS $1: $line"
  else
    report "FAIL $1: $line"
    failed=1
  fi
}
check "sadsplat .spz v3 in @spz-loader/core (RDF)" spz-loader "$out/sadsplat_v3.spz"
st "$out/sadsplat_v3.spz" "$out/st_from_sadsplat_v3.ply" >/dev/null 2>&1
check "sadsplat .spz v3 in splat-transform" ply "$out/st_from_sadsplat_v3.ply"
st "$out/sadsplat_v4.spz" "$out/st_from_sadsplat_v4.ply" >/dev/null 2>&1
check "sadsplat .spz v4 in splat-transform" ply "$out/st_from_sadsplat_v4.ply"

# splat-transform's files read by sadsplat.
n=$("$cli" info "$model" | sed -n 's/^gaussians: //p')
st "$model" "$out/st.spz" >/dev/null 2>&1
st -g cpu "$model" "$out/st.sog" >/dev/null 2>&1
st "$model" "$out/st.compressed.ply" >/dev/null 2>&1
cp "$out/st_from_sadsplat_v3.ply" "$out/st_decoded.ply"  # a plain PLY with +inf opacities
for f in st.spz st.sog st.compressed.ply st_decoded.ply; do
  if "$cli" convert "$out/$f" "$out/sadsplat_from_$f.ply" 2>"$out/$f.err" &&
     m=$("$cli" info "$out/$f" | sed -n 's/^gaussians: //p') && [ "$m" = "$n" ]; then
    report "PASS sadsplat reads splat-transform's $f: $m Gaussians ($(head -c 200 "$out/$f.err"))"
  else
    report "FAIL sadsplat reads splat-transform's $f: $(cat "$out/$f.err")"
    failed=1
  fi
done
check "splat-transform .spz v4 read by sadsplat" ply "$out/sadsplat_from_st.spz.ply"

# sadsplat's .sog read by splat-transform: the same count and bounding box (its codebooks make
# the per-Gaussian error larger than SPZ's, so no attribute-wise check here).
"$cli" convert "$model" "$out/sadsplat.sog"
st -g cpu "$out/sadsplat.sog" "$out/st_from_sadsplat_sog.ply" >/dev/null 2>&1 || true
if [ -f "$out/st_from_sadsplat_sog.ply" ] &&
   m=$("$cli" info "$out/st_from_sadsplat_sog.ply" | sed -n 's/^gaussians: //p') && [ "$m" = "$n" ]; then
  report "PASS splat-transform reads sadsplat's .sog: $m Gaussians, $("$cli" info "$out/st_from_sadsplat_sog.ply" | grep 'bounding box') (model: $("$cli" info "$model" | grep 'bounding box'))"
else
  report "FAIL splat-transform reads sadsplat's .sog"
  failed=1
fi
exit $failed
