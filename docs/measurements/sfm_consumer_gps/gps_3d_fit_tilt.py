#!/usr/bin/python3
"""What the old georeference (the 3D similarity of the GPS alone) would make of an sfm scene:
its tilt against the scene's frame (z up from the scene), from the COLMAP database's GPS priors
(prior_tx/ty/tz = latitude, longitude, altitude) and the scene's camera centres.
usage: gps_3d_fit_tilt.py SCENE_DIR"""
import json, math, sqlite3, sys
import numpy as np

scene = sys.argv[1]
db = sqlite3.connect(scene + '/colmap/database.db')
gps = {n: (la, lo, al) for n, la, lo, al in
       db.execute('select name, prior_tx, prior_ty, prior_tz from images')}
geo = json.load(open(scene + '/georeference.json'))['origin']

def ecef(lat, lon, h):
    a = 6378137.0; f = 1/298.257223563; e2 = f*(2-f)
    la, lo = math.radians(lat), math.radians(lon)
    n = a / math.sqrt(1 - e2*math.sin(la)**2)
    return np.array([(n+h)*math.cos(la)*math.cos(lo), (n+h)*math.cos(la)*math.sin(lo), (n*(1-e2)+h)*math.sin(la)])

la, lo = math.radians(geo['latitude']), math.radians(geo['longitude'])
B = np.array([[-math.sin(lo), math.cos(lo), 0],
              [-math.sin(la)*math.cos(lo), -math.sin(la)*math.sin(lo), math.cos(la)],
              [math.cos(la)*math.cos(lo), math.cos(la)*math.sin(lo), math.sin(la)]])
o = ecef(geo['latitude'], geo['longitude'], geo['altitude'])
C, G = [], []
lines = [l for l in open(scene + '/sparse/0/images.txt') if not l.startswith('#')]
for l in lines[0::2]:
    f = l.split()
    if len(f) < 10 or f[9] not in gps: continue
    w, x, y, z = np.array(list(map(float, f[1:5])))
    R = np.array([[1-2*(y*y+z*z), 2*(x*y-w*z), 2*(x*z+w*y)], [2*(x*y+w*z), 1-2*(x*x+z*z), 2*(y*z-w*x)],
                  [2*(x*z-w*y), 2*(y*z+w*x), 1-2*(x*x+y*y)]])
    C.append(-R.T @ np.array(list(map(float, f[5:8])))); G.append(B @ (ecef(*gps[f[9]]) - o))
C, G = np.array(C), np.array(G)
mc, mg = C.mean(0), G.mean(0)
U, S, Vt = np.linalg.svd((G - mg).T @ (C - mc))
D = np.eye(3); D[2, 2] = np.sign(np.linalg.det(U) * np.linalg.det(Vt))
R = U @ D @ Vt  # scene frame -> the GPS-only 3D fit's frame
up = R.T @ np.array([0, 0, 1.0])
print(f"{len(C)} photos: the 3D fit of the GPS alone is {math.degrees(math.acos(min(1, abs(up[2])))):.2f} deg "
      f"from this scene's z")
