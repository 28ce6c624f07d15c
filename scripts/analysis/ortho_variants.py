#!/usr/bin/env python3
"""The class maps of one set of models under several `eval --ortho` settings, side by side.

usage: ortho_variants.py DIR
DIR holds one folder per scene run, as `scripts/gpu/experiments.sh scene` leaves them under
/tmp/sadsplat-scene (ORTHO=1 ORTHO_VARIANTS="TAG:flags;..."):
<scene>[_<capture>]/results/ortho_<name>.json (the defaults) and ortho_v<TAG>_<name>.json.
Prints per run and setting the class map's mIoU, building IoU and area error, the DSM's RMSE
(all cells, building cells, the ground classes' cells), the building objects' F1 (map / cloud)
and the trimmed share; then per setting the means over the runs and how many runs have their
buildings within +-10 %.
"""
import glob
import json
import os
import re
import sys

GROUND = ("road", "paved", "grass", "ground", "water")


def load(path):
    with open(path) as f:
        return json.load(f)


def summary(j):
    area = j.get("area", {}).get("building", {}).get("relative_error")
    dsm = j.get("dsm", {})
    per = dsm.get("per_class", {})
    ground_sq, ground_n = 0.0, 0
    for c in GROUND:
        if c in per and per[c].get("cells"):
            ground_sq += per[c]["rmse_m"] ** 2 * per[c]["cells"]
            ground_n += per[c]["cells"]
    obj = j.get("objects", {})
    return {
        "miou": j.get("miou"),
        "building_iou": j.get("per_class_iou", {}).get("building"),
        "area": area,
        "dsm": dsm.get("rmse_m"),
        "dsm_building": per.get("building", {}).get("rmse_m"),
        "dsm_ground": (ground_sq / ground_n) ** 0.5 if ground_n else None,
        "f1": obj.get("f1"),
        "cloud_f1": obj.get("cloud_f1"),
        "trimmed": j.get("trimmed_share"),
    }


def fmt(v, scale=1.0, digits=2):
    return "—" if v is None else ("%." + str(digits) + "f") % (scale * v)


def main():
    root = sys.argv[1]
    by_setting = {}
    print("| run | setting | mIoU % | building IoU | building area | DSM RMSE all / building / "
          "ground (m) | objects F1 map / cloud | trimmed % |")
    print("|---|---|---:|---:|---:|---|---|---:|")
    for base in sorted(glob.glob(os.path.join(root, "*", "results", "ortho_*.json"))):
        name = os.path.basename(base)
        m = re.match(r"ortho_([^v].*)\.json$", name)
        if not m or name.startswith(("ortho_s", "ortho_r")) or "blend" in name:
            continue
        run = m.group(1)
        results = os.path.dirname(base)
        folder = os.path.basename(os.path.dirname(results))
        settings = [("default", base)]
        for f in sorted(glob.glob(os.path.join(results, "ortho_v*_%s.json" % run))):
            settings.append((os.path.basename(f)[len("ortho_v"):-len("_%s.json" % run)], f))
        for tag, f in settings:
            try:
                s = summary(load(f))
            except (ValueError, OSError):
                continue
            by_setting.setdefault(tag, []).append(s)
            print("| %s %s | %s | %s | %s | %s | %s / %s / %s | %s / %s | %s |" % (
                folder, run, tag, fmt(s["miou"], 100, 1), fmt(s["building_iou"]),
                fmt(s["area"], 100, 0) + " %" if s["area"] is not None else "—",
                fmt(s["dsm"]), fmt(s["dsm_building"]), fmt(s["dsm_ground"]), fmt(s["f1"]),
                fmt(s["cloud_f1"]), fmt(s["trimmed"], 100, 1)))
    print()
    print("| setting | runs | mean mIoU % | mean building IoU | mean abs area error | within "
          "+-10 % | mean DSM RMSE all / building / ground (m) | mean F1 map / cloud |")
    print("|---|---:|---:|---:|---:|---:|---|---|")
    for tag, rows in by_setting.items():
        def mean(key, scale=1.0):
            v = [r[key] for r in rows if r[key] is not None]
            return fmt(sum(v) / len(v), scale, 2 if scale == 1.0 else 1) if v else "—"
        areas = [r["area"] for r in rows if r["area"] is not None]
        within = sum(1 for a in areas if abs(a) <= 0.10)
        abs_area = "%.1f %%" % (100 * sum(abs(a) for a in areas) / len(areas)) if areas else "—"
        print("| %s | %d | %s | %s | %s | %d of %d | %s / %s / %s | %s / %s |" % (
            tag, len(rows), mean("miou", 100), mean("building_iou"), abs_area, within,
            len(areas), mean("dsm"), mean("dsm_building"), mean("dsm_ground"), mean("f1"),
            mean("cloud_f1")))


if __name__ == "__main__":
    main()
