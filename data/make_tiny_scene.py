#!/usr/bin/env python3
"""Writes data/tiny_scene: the small fixture scene used by the tests and `sadsplat demo`.

Pure standard library (run with Debian's /usr/bin/python3), deterministic. A ground plane with a
road strip, grass, and one box building, seen by 8 orbiting pinhole cameras at 64x48; ray cast
per pixel, so images, label maps and the sparse points agree exactly. Also writes the same COLMAP
model in binary form to data/tiny_scene_colmap_bin/ (an independent writer for the reader tests).

usage: make_tiny_scene.py [OUT_DIR]   (default: the directory of this script)
"""
import json
import math
import os
import random
import struct
import sys
import zlib

W, H, F = 64, 48, 52.0
NUM_VIEWS = 8
CLASSES = [
    {"name": "road", "color": [128, 64, 128], "prompt": "an asphalt road"},
    {"name": "grass", "color": [0, 160, 0], "prompt": "grass"},
    {"name": "building", "color": [220, 20, 60], "prompt": "a building roof or wall"},
]
BOX = ((0.4, 0.4, 0.0), (1.3, 1.2, 0.7))
EXTENT = 2.0
SKY = (170, 200, 235)


def png(path, width, height, rows, gray=False):
    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    def chunk(tag, data):
        return struct.pack(">I", len(data)) + tag + data + struct.pack(">I", zlib.crc32(tag + data))
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0 if gray else 2, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(raw, 9))
                + chunk(b"IEND", b""))


def sub(a, b): return (a[0] - b[0], a[1] - b[1], a[2] - b[2])
def dot(a, b): return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
def cross(a, b): return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
def norm(a):
    n = math.sqrt(dot(a, a))
    return (a[0] / n, a[1] / n, a[2] / n)


def hit(origin, d):
    """Nearest surface along the ray: (t, class id, normal) or None."""
    best = None
    # Box (slab test).
    t0, t1, axis_hit, sign = -1e30, 1e30, 0, 1
    inside = True
    for a in range(3):
        if abs(d[a]) < 1e-12:
            if origin[a] < BOX[0][a] or origin[a] > BOX[1][a]:
                inside = False
            continue
        ta, tb = (BOX[0][a] - origin[a]) / d[a], (BOX[1][a] - origin[a]) / d[a]
        s = -1 if ta < tb else 1
        if ta > tb:
            ta, tb = tb, ta
        if ta > t0:
            t0, axis_hit, sign = ta, a, s
        t1 = min(t1, tb)
    if inside and t0 <= t1 and t0 > 1e-6:
        n = [0.0, 0.0, 0.0]
        n[axis_hit] = float(sign)
        best = (t0, 2, tuple(n))
    # Ground plane z = 0 inside the extent.
    if d[2] < -1e-9:
        t = -origin[2] / d[2]
        p = (origin[0] + t * d[0], origin[1] + t * d[1])
        if abs(p[0]) <= EXTENT and abs(p[1]) <= EXTENT and (best is None or t < best[0]):
            best = (t, 0 if abs(p[1] + 0.3 * p[0]) < 0.35 else 1, (0.0, 0.0, 1.0))
    return best


def shade(cls, p, n):
    base = CLASSES[cls]["color"]
    texture = 0.85 + 0.15 * ((int(math.floor(p[0] * 6)) + int(math.floor(p[1] * 6)) + int(math.floor(p[2] * 6))) % 2)
    light = 0.55 + 0.45 * max(0.0, dot(n, norm((0.4, 0.3, 1.0))))
    return tuple(min(255, int(c * texture * light + 20)) for c in base)


def camera(i):
    angle = 2 * math.pi * i / NUM_VIEWS
    radius, height = 4.5 + 0.3 * math.sin(3 * angle), 3.2 + 0.2 * math.cos(2 * angle)
    center = (radius * math.cos(angle), radius * math.sin(angle), height)
    forward = norm(sub((0.2, 0.1, 0.0), center))
    right = norm(cross(forward, (0, 0, 1)))
    down = cross(forward, right)
    R = (right, down, forward)
    t = tuple(-dot(R[r], center) for r in range(3))
    return center, R, t


def quaternion(R):
    tr = R[0][0] + R[1][1] + R[2][2]
    if tr > 0:
        s = math.sqrt(tr + 1.0) * 2
        q = (0.25 * s, (R[2][1] - R[1][2]) / s, (R[0][2] - R[2][0]) / s, (R[1][0] - R[0][1]) / s)
    else:
        i = max(range(3), key=lambda k: R[k][k])
        j, k = (i + 1) % 3, (i + 2) % 3
        s = math.sqrt(1.0 + R[i][i] - R[j][j] - R[k][k]) * 2
        q = [0.0] * 4
        q[0] = (R[k][j] - R[j][k]) / s
        q[1 + i] = 0.25 * s
        q[1 + j] = (R[j][i] + R[i][j]) / s
        q[1 + k] = (R[k][i] + R[i][k]) / s
        q = tuple(q)
    return q if q[0] >= 0 else tuple(-v for v in q)


def ray(center, R, u, v):
    dc = ((u - W / 2) / F, (v - H / 2) / F, 1.0)
    return norm(tuple(R[0][a] * dc[0] + R[1][a] * dc[1] + R[2][a] * dc[2] for a in range(3)))


def project(center, R, t, p):
    pc = tuple(dot(R[r], p) + t[r] for r in range(3))
    if pc[2] <= 1e-6:
        return None
    return (F * pc[0] / pc[2] + W / 2, F * pc[1] / pc[2] + H / 2, pc[2])


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.dirname(os.path.abspath(__file__))
    scene = os.path.join(out, "tiny_scene")
    for sub_dir in ("images", "labels", "sparse/0"):
        os.makedirs(os.path.join(scene, sub_dir), exist_ok=True)
    bin_dir = os.path.join(out, "tiny_scene_colmap_bin")
    os.makedirs(bin_dir, exist_ok=True)
    cams = [camera(i) for i in range(NUM_VIEWS)]
    names = ["view_%03d.png" % i for i in range(NUM_VIEWS)]
    labelled = {0, 3}
    for i, (center, R, t) in enumerate(cams):
        rgb_rows, label_rows = [], []
        for v in range(H):
            rgb, lab = [], []
            for u in range(W):
                d = ray(center, R, u + 0.5, v + 0.5)
                h = hit(center, d)
                if h is None:
                    rgb += SKY
                    lab.append(255)
                else:
                    p = tuple(center[a] + h[0] * d[a] for a in range(3))
                    rgb += shade(h[1], p, h[2])
                    lab.append(h[1])
            rgb_rows.append(rgb)
            label_rows.append(lab)
        png(os.path.join(scene, "images", names[i]), W, H, rgb_rows)
        # Every view has its ground truth (the test views need it); split.json says which
        # training views are labelled, i.e. supervise training.
        png(os.path.join(scene, "labels", names[i]), W, H, label_rows, gray=True)

    # Sparse points: surface samples seen (unoccluded, in frame) from at least two views.
    rng = random.Random(7)
    points, tracks, points2d = [], [], [[] for _ in range(NUM_VIEWS)]
    while len(points) < 400:
        kind = rng.random()
        if kind < 0.7:
            p = (rng.uniform(-EXTENT, EXTENT), rng.uniform(-EXTENT, EXTENT), 0.0)
            if BOX[0][0] <= p[0] <= BOX[1][0] and BOX[0][1] <= p[1] <= BOX[1][1]:
                continue
            n = (0.0, 0.0, 1.0)
            cls = 0 if abs(p[1] + 0.3 * p[0]) < 0.35 else 1
        else:
            p = (rng.uniform(BOX[0][0], BOX[1][0]), rng.uniform(BOX[0][1], BOX[1][1]), BOX[1][2])
            n, cls = (0.0, 0.0, 1.0), 2
        track = []
        for i, (center, R, t) in enumerate(cams):
            uvz = project(center, R, t, p)
            if uvz is None or not (0 <= uvz[0] < W and 0 <= uvz[1] < H):
                continue
            d = norm(sub(p, center))
            h = hit(center, d)
            if h is not None and abs(h[0] - math.sqrt(dot(sub(p, center), sub(p, center)))) < 1e-4:
                track.append((i, uvz))
        if len(track) < 2:
            continue
        pid = len(points) + 1
        color = shade(cls, p, n)
        entries = []
        for i, uvz in track:
            entries.append((i + 1, len(points2d[i])))
            points2d[i].append((uvz[0], uvz[1], pid))
        points.append((pid, p, color))
        tracks.append(entries)

    sparse = os.path.join(scene, "sparse", "0")
    with open(os.path.join(sparse, "cameras.txt"), "w") as f:
        f.write("# Camera list with one line of data per camera:\n")
        f.write("1 PINHOLE %d %d %.17g %.17g %.17g %.17g\n" % (W, H, F, F, W / 2, H / 2))
    with open(os.path.join(sparse, "images.txt"), "w") as f:
        f.write("# Image list with two lines of data per image:\n")
        for i, (center, R, t) in enumerate(cams):
            q = quaternion(R)
            f.write("%d %s %s 1 %s\n" % (i + 1, " ".join("%.17g" % v for v in q),
                                          " ".join("%.17g" % v for v in t), names[i]))
            f.write(" ".join("%.17g %.17g %d" % e for e in points2d[i]) + "\n")
    with open(os.path.join(sparse, "points3D.txt"), "w") as f:
        f.write("# 3D point list with one line of data per point:\n")
        for (pid, p, c), track in zip(points, tracks):
            f.write("%d %.17g %.17g %.17g %d %d %d 0.5 %s\n" % (
                pid, p[0], p[1], p[2], c[0], c[1], c[2],
                " ".join("%d %d" % e for e in track)))

    with open(os.path.join(bin_dir, "cameras.bin"), "wb") as f:
        f.write(struct.pack("<QIiQQ4d", 1, 1, 1, W, H, F, F, W / 2, H / 2))
    with open(os.path.join(bin_dir, "images.bin"), "wb") as f:
        f.write(struct.pack("<Q", NUM_VIEWS))
        for i, (center, R, t) in enumerate(cams):
            f.write(struct.pack("<I4d3dI", i + 1, *quaternion(R), *t, 1))
            f.write(names[i].encode() + b"\x00")
            f.write(struct.pack("<Q", len(points2d[i])))
            for x, y, pid in points2d[i]:
                f.write(struct.pack("<ddQ", x, y, pid))
    with open(os.path.join(bin_dir, "points3D.bin"), "wb") as f:
        f.write(struct.pack("<Q", len(points)))
        for (pid, p, c), track in zip(points, tracks):
            f.write(struct.pack("<Q3d3Bd", pid, *p, *c, 0.5))
            f.write(struct.pack("<Q", len(track)))
            for e in track:
                f.write(struct.pack("<II", *e))

    with open(os.path.join(scene, "classes.json"), "w") as f:
        json.dump({"classes": CLASSES}, f, indent=2)
        f.write("\n")
    test_views = {2, 5}
    with open(os.path.join(scene, "split.json"), "w") as f:
        json.dump({"train": [n for i, n in enumerate(names) if i not in test_views],
                   "test": [names[i] for i in sorted(test_views)],
                   "labelled": [names[i] for i in sorted(labelled)]}, f, indent=2)
        f.write("\n")
    print("wrote %s: %d views, %d points" % (scene, NUM_VIEWS, len(points)))


if __name__ == "__main__":
    main()
