#!/usr/bin/env bash
# A trained run on the globe, checked with clients nobody on this project wrote:
#   bash scripts/interop/globe_check.sh RUN OUT_DIR [MAX_SPLATS]
# 1. sadsplat writes RUN as a 3D Tiles tileset (OUT/tileset, SPZ content), the same coloured by
#    class (OUT/tileset_classes), and as one .glb with the SPZ payload and with plain accessors;
#    splat-transform writes its own .glb of the model (the validator's control).
# 2. check_clients.mjs: Khronos' gltf-validator on every GLB, loaders.gl's GLTFLoader and
#    Tiles3DLoader, Niantic's SPZ decoder on the payload against the plain accessors.
# 3. CesiumJS in headless Chromium (SwiftShader WebGL, no imagery: offline) loads the tilesets from
#    straight above: far (OUT/cesium_far.png), near (OUT/cesium_near.png), near by class
#    (OUT/cesium_classes.png); it reports the tiles drawn and where it placed the root box's
#    centre against sadsplat's own geodesy (within 1 m to pass). A local tileset (no
#    georeference) is placed at lat 0, lon 0.
# Prints one line per check and OUT/summary.txt; exit 1 if any check fails. Needs chromium, node,
# npm and the npm registry (the tools go to .deps/globe-tools, git-ignored). Not part of CI.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
run=$(cd "$1" && pwd)
out=$(mkdir -p "$2" && cd "$2" && pwd)
max_splats=${3:-65536}
cli=${SADSPLAT_CLI:-$root/build/bin/sadsplat}
tools=$root/.deps/globe-tools
command -v chromium >/dev/null ||
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends chromium >/dev/null
if [ ! -d "$tools/node_modules/cesium" ]; then
  mkdir -p "$tools"
  (cd "$tools" && npm init -y >/dev/null && npm install --no-audit --no-fund cesium@1.145.0 \
     @playcanvas/splat-transform@3.7.0 gltf-validator@2.0.0-dev.3.10 @loaders.gl/core@4.5.4 \
     @loaders.gl/gltf@4.5.4 @loaders.gl/3d-tiles@4.5.4 @spz-loader/core@0.3.1 >/dev/null 2>&1)
fi
cp "$root"/scripts/interop/globe/check_clients.mjs "$root"/scripts/web_viewer/cdp_screenshot.mjs "$tools/"
: > "$out/summary.txt"
report() { echo "$1" | tee -a "$out/summary.txt"; }
report "# $(date -u +%Y-%m-%d) $run on the globe (CesiumJS 1.145.0, headless Chromium $(chromium --version 2>/dev/null | awk '{print $2}'))"

rm -rf "$out/tileset" "$out/tileset_classes"
"$cli" tiles "$run" --out "$out/tileset" --max-splats "$max_splats" 2>"$out/tiles.log" | tee -a "$out/summary.txt"
"$cli" tiles "$run" --out "$out/tileset_classes" --max-splats "$max_splats" --color-by-class \
  2>>"$out/tiles.log" >/dev/null
"$cli" convert "$run" "$out/model.glb" 2>/dev/null
"$cli" convert "$run" "$out/model_plain.glb" --glb-no-spz 2>/dev/null
(cd "$tools" && npx splat-transform -q -w "$run/model.ply" "$out/st.glb" >/dev/null 2>&1) || true
failed=0
(cd "$tools" && node check_clients.mjs "$out" "$out/st.glb") | tee -a "$out/summary.txt" || failed=1

# CesiumJS.
www=$tools/www
rm -rf "$www" && mkdir -p "$www"
ln -s "$tools/node_modules/cesium/Build/Cesium" "$www/Cesium"
ln -s "$out/tileset" "$www/tileset"
ln -s "$out/tileset_classes" "$www/tileset_classes"
cp "$root/scripts/interop/globe/cesium.html" "$www/"
local=0; grep -q '"georeferenced": false' "$out/tileset/tileset.json" && local=1
port=$((20000 + RANDOM % 20000)); debug=$((port + 1))
(cd "$www" && exec python3 -m http.server "$port" --bind 127.0.0.1 >/dev/null 2>&1) &
server=$!
chromium --headless=new --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader \
  --ignore-gpu-blocklist --remote-debugging-port="$debug" --user-data-dir="$tools/profile" \
  about:blank >/dev/null 2>&1 &
browser=$!
trap 'kill $server $browser 2>/dev/null || true' EXIT
for _ in $(seq 60); do curl -sf "http://127.0.0.1:$debug/json/version" >/dev/null && break; sleep 0.5; done
radius=$(python3 -c "import json;print(json.load(open('$out/tileset/tileset.json'))['extras']['look_at']['radius'])")
shot() {  # name tileset range
  local state
  state=$(cd "$tools" && node --experimental-websocket cdp_screenshot.mjs "$debug" \
    "http://127.0.0.1:$port/cesium.html?tileset=$2/tileset.json&range=$3&local=$local" "$out/cesium_$1.png" 150)
  echo "${state#ready }" > "$out/cesium_$1.json"
  case "$state" in
    ready*) report "PASS CesiumJS $1 (camera $3 m from the scene's centre): $(python3 -c "
import json,sys; r=json.load(open('$out/cesium_$1.json'))
print('%d tiles drawn (%s), all loaded %s, root box centre %.3f m from sadsplat\'s geodesy, %.1f s' % (len(r['tiles_drawn']), ' '.join(r['tiles_drawn'][:8]), r['all_loaded'], r['root_centre_offset_m'] if r['root_centre_offset_m'] is not None else -1, r['seconds']))")" ;;
    *) report "FAIL CesiumJS $1: $state"; failed=1 ;;
  esac
}
far=$(python3 -c "print(round(12 * $radius, 1))")
near=$(python3 -c "print(round(2.5 * $radius, 1))")
shot far tileset "$far"
shot near tileset "$near"
shot classes tileset_classes "$near"
python3 - "$out" "$local" <<'PY' | tee -a "$out/summary.txt" || failed=1
import json, sys
out, local = sys.argv[1], sys.argv[2] == '1'
far, near = (json.load(open(f'{out}/cesium_{n}.json')) for n in ('far', 'near'))
level = lambda r: max(int(t.split('_')[0]) for t in r['tiles_drawn']) if r['tiles_drawn'] else -1
ok = bool(far['tiles_drawn']) and bool(near['tiles_drawn']) and level(near) > level(far)
print(('PASS' if ok else 'FAIL') + f" refinement: deepest level drawn far {level(far)}, near {level(near)}")
if not local:
    off = near['root_centre_offset_m']
    ok2 = off is not None and off < 1.0
    print(('PASS' if ok2 else 'FAIL') + f" placement: CesiumJS puts the root box centre {off:.4f} m from sadsplat's fromEnu of it (lat {near['centre']['latitude']:.7f}, lon {near['centre']['longitude']:.7f})")
    ok = ok and ok2
sys.exit(0 if ok else 1)
PY
exit $failed
