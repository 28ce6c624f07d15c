#!/usr/bin/env bash
# sadsplat's transforms.json reader against a writer nobody on this project wrote: instant-ngp's
# scripts/colmap2nerf.py turns a scene directory's COLMAP text model into a transforms.json (its
# own axis flips, up-vector rotation, recentring and scaling); sadsplat imports both, and the
# cameras must agree up to one similarity (intrinsics equal, every camera's rotation off by the
# same world rotation, camera centres related by one scale + rotation + shift).
#   bash scripts/interop/transforms_check.sh SCENE_DIR COLMAP2NERF_PY OUT_DIR
# SCENE_DIR: a scene with images/ and sparse/0 as text (what `sadsplat sfm` writes).
# COLMAP2NERF_PY: instant-ngp's scripts/colmap2nerf.py (peer source, never committed; it needs
# numpy, and cv2 only for a sharpness score, which a stub in OUT_DIR stands in for).
# Prints the deviations and PASS or FAIL; exits 1 on FAIL. Not part of CI.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
scene=$(readlink -f "$1")
peer=$(readlink -f "$2")
out=$(mkdir -p "$3" && cd "$3" && pwd)
cli=${SADSPLAT_CLI:-$root/build/bin/sadsplat}
python=${PYTHON:-/usr/bin/python3}

# A scene folder with the same images and only the transforms.json instant-ngp writes.
rm -rf "$out/ngp_scene" && mkdir -p "$out/ngp_scene" "$out/stub"
ln -s "$scene/images" "$out/ngp_scene/images"
cat > "$out/stub/cv2.py" <<'PY'
# Stands in for OpenCV in colmap2nerf.py, which uses it only for a per-image sharpness score.
import numpy as np
COLOR_BGR2GRAY = 6
CV_64F = 6
def imread(path): return np.zeros((4, 4, 3))
def cvtColor(image, code): return image[..., 0]
def Laplacian(image, depth): return image
PY
(cd "$out/ngp_scene" && PYTHONPATH="$out/stub" "$python" "$peer" --text "$scene/sparse/0" \
   --images images --out transforms.json --aabb_scale 16 > "$out/colmap2nerf.log" 2>&1)

"$cli" info --cameras "$scene" > "$out/cameras_colmap.csv"
"$cli" info --cameras "$out/ngp_scene" > "$out/cameras_transforms.csv"
"$python" - "$out/cameras_colmap.csv" "$out/cameras_transforms.csv" <<'PY'
import csv, sys
import numpy as np

def load(path):
    rows = {r["name"]: r for r in csv.DictReader(open(path))}
    return rows

def rotation(q):
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                     [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                     [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])

a, b = load(sys.argv[1]), load(sys.argv[2])
names = sorted(a)
ok = sorted(b) == names
print("views: %d (COLMAP) %d (transforms.json), same names: %s" % (len(a), len(b), ok))
intrinsics = max(abs(float(a[n][k]) - float(b[n][k])) for n in names for k in ("fx", "fy", "cx", "cy"))
sizes = all(a[n]["width"] == b[n]["width"] and a[n]["height"] == b[n]["height"] for n in names)
print("max intrinsics difference: %.3g px, same sizes: %s" % (intrinsics, sizes))
R = {}; C = {}
for rows, tag in ((a, "a"), (b, "b")):
    for n in names:
        q = np.array([float(rows[n][k]) for k in ("qw", "qx", "qy", "qz")])
        t = np.array([float(rows[n][k]) for k in ("tx", "ty", "tz")])
        Rn = rotation(q)
        R[tag, n] = Rn
        C[tag, n] = -Rn.T @ t
# world_b = s Q world_a + shift  =>  R_b = R_a Q^T for every camera.
Qs = [R["b", n].T @ R["a", n] for n in names]   # = Q for every camera
Q = Qs[0]
angle = max(np.degrees(np.arccos(np.clip((np.trace(Q.T @ Qi) - 1) / 2, -1, 1))) for Qi in Qs)
ca = np.array([C["a", n] for n in names]); cb = np.array([C["b", n] for n in names])
ma, mb = ca.mean(0), cb.mean(0)
s = np.linalg.norm(cb - mb) / np.linalg.norm((ca - ma) @ Q.T)
residual = np.abs((cb - mb) - s * (ca - ma) @ Q.T).max() / (s * np.abs(ca - ma).max())
print("common world rotation: spread %.3g deg; centres after one similarity (scale %.4g): "
      "max residual %.3g of the camera spread" % (angle, s, residual))
passed = ok and sizes and intrinsics < 1e-6 and angle < 1e-3 and residual < 1e-4
print("PASS" if passed else "FAIL")
sys.exit(0 if passed else 1)
PY
