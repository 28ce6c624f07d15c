#!/usr/bin/env bash
# The scene cache (version 3, docs/formats.md) read by a decoder written from the format's text
# alone: the NumPy reader of scripts/gsplat_reference/train_gsplat.py (its torch calls stubbed),
# against the PNG images and label maps that `sadsplat synth` writes next to the cache. Every
# pixel must match; also checks the cameras' count, the classes and the points' count against
# `sadsplat info`.
#   bash scripts/interop/scene_cache_check.sh OUT_DIR [KIND=city] [SEED=0]
# Needs python3 with numpy and PIL (Debian: python3-numpy python3-pil). Not part of CI.
# Prints the differences and PASS or FAIL; exits 1 on FAIL.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
out=$(mkdir -p "$1" && cd "$1" && pwd)
kind=${2:-city}
seed=${3:-0}
cli=${SADSPLAT_CLI:-$root/build/bin/sadsplat}
python=${PYTHON:-/usr/bin/python3}

rm -rf "$out/scene" "$out/scene.cache"
"$cli" synth --kind "$kind" --seed "$seed" --preset demo --out "$out/scene" --cache "$out/scene.cache" > "$out/synth.log"
"$cli" info "$out/scene.cache" > "$out/info.txt"
"$python" - "$root/scripts/gsplat_reference/train_gsplat.py" "$out/scene.cache" "$out/scene" "$out/info.txt" <<'PY'
import importlib.util, re, sys, types
import numpy as np
from PIL import Image
reader, cache, scene, info = sys.argv[1:5]
torch = types.ModuleType("torch")  # the reader's torch calls, on NumPy arrays
torch.from_numpy = lambda a: a
torch.tensor = lambda rows, dtype=None: np.array(rows, dtype=np.float32)
torch.float32 = np.float32
nn = types.ModuleType("torch.nn"); nn.functional = types.ModuleType("torch.nn.functional")
sys.modules.update({"torch": torch, "torch.nn": nn, "torch.nn.functional": nn.functional})
spec = importlib.util.spec_from_file_location("reference", reader)
module = importlib.util.module_from_spec(spec)
spec.loader.exec_module(module)
classes, views, points = module.read_cache(cache)
failures = []
text = open(info).read()
want_views = int(re.search(r"views: (\d+)", text).group(1))
want_points = int(re.search(r"sparse points: (\d+)", text).group(1))
if len(views) != want_views: failures.append(f"{len(views)} views, sadsplat info says {want_views}")
if len(points) != want_points: failures.append(f"{len(points)} points, sadsplat info says {want_points}")
rgb_diff = label_diff = labelled = 0
for v in views:
    png = np.array(Image.open(f"{scene}/images/{v['name']}").convert("RGB"))
    rgb_diff += int((png != v["rgb"]).any(axis=2).sum())
    if v["labels"] is not None:
        labelled += 1
        label_diff += int((np.array(Image.open(f"{scene}/labels/{v['name']}")) != v["labels"]).sum())
    if set(np.unique(v["mask"])) - {0, 255}: failures.append(f"{v['name']}: mask values other than 0/255")
print(f"{len(views)} views, {labelled} label maps, {len(classes)} classes, {len(points)} points")
print(f"pixels that differ from the PNGs: RGB {rgb_diff}, labels {label_diff}")
if rgb_diff or label_diff: failures.append("decoded pixels differ from the scene's PNGs")
if labelled == 0: failures.append("no label map decoded")
print("FAIL: " + "; ".join(failures) if failures else "PASS")
sys.exit(1 if failures else 0)
PY
