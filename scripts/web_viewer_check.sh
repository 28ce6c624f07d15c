#!/usr/bin/env bash
# Loads a trained model in two web splat viewers from npm, in headless Chromium, as a user
# sharing it on the web would: @mkkellogg/gaussian-splats-3d (.ply, .splat, .spz version 2) and
# @sparkjsdev/spark (.ply, .splat, .spz version 3). Writes OUT/<viewer>_<file>.png, and
# OUT/summary.txt: file sizes, each page's state, the share of non-background pixels, distinct
# colours, and the mean difference of each render to the same viewer's .ply render.
#   bash scripts/web_viewer_check.sh RUN_DIR OUT_DIR
# Needs (Debian bookworm, root): chromium, nodejs, npm (installed here when missing) and the npm
# registry (the viewers are installed into .deps/web, git-ignored).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
run=$(cd "$1" && pwd)
out=$(mkdir -p "$2" && cd "$2" && pwd)
cli=${SADSPLAT_CLI:-$root/build/bin/sadsplat}
web=$root/.deps/web
missing=()
command -v chromium >/dev/null || missing+=(chromium)
command -v node >/dev/null || missing+=(nodejs)
command -v npm >/dev/null || missing+=(npm)
if [ ${#missing[@]} -gt 0 ]; then
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
mkdir -p "$web"
if [ ! -d "$web/node_modules/@sparkjsdev/spark" ]; then
  (cd "$web" && npm init -y >/dev/null && npm install --no-audit --no-fund \
     @mkkellogg/gaussian-splats-3d@0.4.7 @sparkjsdev/spark@2.2.0 three@0.187.0 pngjs@7 >/dev/null)
fi
cp "$root"/scripts/web_viewer/*.html "$root"/scripts/web_viewer/*.mjs "$web/"

# The model in each format.
cp "$run/model.ply" "$web/model.ply"
"$cli" convert "$run/model.ply" "$web/model.splat" >/dev/null
"$cli" convert "$run/model.ply" "$web/model.spz" >/dev/null
"$cli" convert "$run/model.ply" "$web/model_v2.spz" --spz-version 2 >/dev/null

# The camera: looking at the median centre from 45 degrees above, at a distance of the spread
# of the middle half of the Gaussians (far floaters do not set the view). z is up.
read -r centre eye < <("$cli" info "$run/model.ply" >/dev/null && node -e '
  const fs = require("fs");
  const b = fs.readFileSync(process.argv[1]);
  const n = b.length / 32, xs = [[], [], []];
  for (let i = 0; i < n; ++i) for (let k = 0; k < 3; ++k) xs[k].push(b.readFloatLE(32 * i + 4 * k));
  const q = (a, p) => { a.sort((u, v) => u - v); return a[Math.floor(p * (a.length - 1))]; };
  const lo = xs.map((a) => q(a, 0.25)), hi = xs.map((a) => q(a, 0.75));
  const c = xs.map((a) => q(a, 0.5));
  const r = 1.6 * Math.hypot(hi[0] - lo[0], hi[1] - lo[1]);
  console.log(c.map((v) => v.toFixed(3)).join(","),
              [c[0], c[1] - r, c[2] + r].map((v) => v.toFixed(3)).join(","));
' "$web/model.splat")

port=$((20000 + RANDOM % 20000))
debug=$((port + 1))
(cd "$web" && exec python3 -m http.server "$port" --bind 127.0.0.1 >/dev/null 2>&1) &
server=$!
chromium --headless=new --no-sandbox --use-angle=swiftshader --enable-unsafe-swiftshader \
  --ignore-gpu-blocklist --remote-debugging-port="$debug" --user-data-dir="$web/profile" \
  about:blank >/dev/null 2>&1 &
browser=$!
trap 'kill $server $browser 2>/dev/null || true' EXIT
for _ in $(seq 50); do curl -sf "http://127.0.0.1:$debug/json/version" >/dev/null && break; sleep 0.2; done

{
  echo "# $(date -u +%Y-%m-%d) web viewers on $run (headless Chromium $(chromium --version 2>/dev/null | awk '{print $2}'), SwiftShader WebGL)"
  echo "file sizes (bytes): ply $(stat -c %s "$web/model.ply") splat $(stat -c %s "$web/model.splat") spz(v3) $(stat -c %s "$web/model.spz") spz(v2) $(stat -c %s "$web/model_v2.spz")"
  echo "viewer file state non_background_share distinct_colours mean_abs_diff_to_ply"
} >"$out/summary.txt"
status=0
for spec in "gs3d model.ply" "gs3d model.splat" "gs3d model_v2.spz" \
            "spark model.ply" "spark model.splat" "spark model.spz"; do
  set -- $spec
  png="$out/${1}_${2/./_}.png"
  # .spz holds RUB axes (the spec), the PLY RDF: the viewers load both as they are, so the .spz
  # is turned 180 degrees about x (viewer.html's flip) to be compared under the same camera.
  flip=0; [ "${2##*.}" = spz ] && flip=1
  state=$(cd "$web" && node --experimental-websocket cdp_screenshot.mjs "$debug" \
    "http://127.0.0.1:$port/viewer.html?viewer=$1&file=$2&c=$centre&e=$eye&flip=$flip" "$png" 120 2>/dev/null)
  stats=$(cd "$web" && node png_stats.mjs "$png" "$out/${1}_model_ply.png")
  echo "$1 $2 $state $stats" | tee -a "$out/summary.txt"
  share=${stats%% *}
  if [ "$state" != "ready" ] || awk -v s="$share" 'BEGIN { exit !(s < 0.05) }'; then status=1; fi
done
exit $status
