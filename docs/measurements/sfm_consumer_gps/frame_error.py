#!/usr/bin/python3
"""Frame error of an sfm scene against the synthetic truth: camera centres (COLMAP text models),
the recovered ones in east-north-up metres around georeference.json's origin, the true ones in the
world's x, y, z (east, north, up around the place the photos were given). Prints the similarity
truth -> recovered: tilt of up, heading, scale; and the RMS of the centres after it.
usage: frame_error.py TRUE_SPARSE_DIR SCENE_DIR [gps]   (gps: the report's GPS-only frame)"""
import json, math, sys
import numpy as np

def centres(images_txt):
    out = {}
    lines = [l for l in open(images_txt) if not l.startswith('#')]
    for l in lines[0::2]:
        f = l.split()
        if len(f) < 10: continue
        q = np.array(list(map(float, f[1:5]))); t = np.array(list(map(float, f[5:8])))
        w, x, y, z = q / np.linalg.norm(q)
        R = np.array([[1-2*(y*y+z*z), 2*(x*y-w*z), 2*(x*z+w*y)],
                      [2*(x*y+w*z), 1-2*(x*x+z*z), 2*(y*z-w*x)],
                      [2*(x*z-w*y), 2*(y*z+w*x), 1-2*(x*x+y*y)]])
        out[f[9].rsplit('.', 1)[0]] = -R.T @ t
    return out

def ecef(lat, lon, h):
    a = 6378137.0; f = 1/298.257223563; e2 = f*(2-f)
    la, lo = math.radians(lat), math.radians(lon)
    n = a / math.sqrt(1 - e2*math.sin(la)**2)
    return np.array([(n+h)*math.cos(la)*math.cos(lo), (n+h)*math.cos(la)*math.sin(lo), (n*(1-e2)+h)*math.sin(la)])

def enu_basis(lat, lon):
    la, lo = math.radians(lat), math.radians(lon)
    return np.array([[-math.sin(lo), math.cos(lo), 0],
                     [-math.sin(la)*math.cos(lo), -math.sin(la)*math.sin(lo), math.cos(la)],
                     [math.cos(la)*math.cos(lo), math.cos(la)*math.sin(lo), math.sin(la)]])

truth = centres(sys.argv[1] + '/images.txt')
scene = sys.argv[2]
rec = centres(scene + '/sparse/0/images.txt')
geo = json.load(open(scene + '/georeference.json'))
sim = geo['sfm_to_local']
if len(sys.argv) > 3:  # the GPS-only frame: undo the final frame, apply the report's GPS frame
    gps = json.load(open(scene + '/sfm_report.json'))['gps_georeference']['sfm_to_local']
    Rf = np.array(sim['rotation']).reshape(3, 3); tf = np.array(sim['translation'])
    Rg = np.array(gps['rotation']).reshape(3, 3); tg = np.array(gps['translation'])
    for k in rec:
        c = Rf.T @ (rec[k] - tf) / sim['scale']
        rec[k] = gps['scale'] * Rg @ c + tg
place = (47.3769, 8.5417, 420.0)
o = geo['origin']
B = enu_basis(o['latitude'], o['longitude'])
Bp = enu_basis(*place[:2])
names = sorted(set(truth) & set(rec))
T = np.array([B @ (ecef(*place) + Bp.T @ truth[n] - ecef(o['latitude'], o['longitude'], o['altitude'])) for n in names])
X = np.array([rec[n] for n in names])
mt, mx = T.mean(0), X.mean(0)
C = (X - mx).T @ (T - mt) / len(names)
U, S, Vt = np.linalg.svd(C)
D = np.eye(3); D[2, 2] = np.sign(np.linalg.det(U) * np.linalg.det(Vt))
R = U @ D @ Vt
s = np.trace(np.diag(S) @ D) / ((T - mt)**2).sum(1).mean()
t = mx - s * R @ mt
res = X - (s * (R @ T.T).T + t)
up = R @ np.array([0, 0, 1.0]); east = R @ np.array([1.0, 0, 0])
print(f"{len(names)} cameras: tilt {math.degrees(math.acos(min(1, up[2]))):.3f} deg, heading {math.degrees(math.atan2(east[1], east[0])):.3f} deg, "
      f"scale {100*(s-1):+.3f} %, translation {np.linalg.norm(t):.2f} m (horizontal {np.linalg.norm(t[:2]):.2f}, vertical {t[2]:+.2f}), "
      f"centre RMS after the similarity {math.sqrt((res**2).sum(1).mean()):.3f} m")
