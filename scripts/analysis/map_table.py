#!/usr/bin/env python3
"""The benchmark's 3D and map table from `scripts/gpu/experiments.sh scene` results.

usage: map_table.py DIR [ORTHO]
DIR holds one folder per scene run, as experiments.sh leaves them under /tmp/sadsplat-scene:
<scene>[_pl][_<capture>][_l<labelled>]/results/{metrics,ortho,3d}_<name>.json (ORTHO=1 THREED=1). Prints a
Markdown table: per scene, capture and run the view mIoU, the cloud's 3D point mIoU and
geometry, the class map's mIoU and its gap to the views, the DSM's RMSE on roofs and roads,
the building area error and object F1 (map regions; the cloud's Euclidean clusters).
A goals table follows for the full method's runs: each of the benchmark's goals (class map at
most 5 points below the views, buildings within +-10 %, DSM RMSE on roofs and on the worst
ground class (a class the map does not count as raised, water aside) at most 2 x the map's
cell, 3D point mIoU at least the views' - 5, 90 % of opaque Gaussians within 0.5 m, map building
objects F1 >= 0.8) with the measured value, `ok` or the miss, and how many runs meet each.
Where the class maps carry `miou_within` and the DSM `off_step_rmse_m` (eval --ortho since
those keys exist), a second table says where the gaps lie: the class map near the centre, the
DSM away from the walls and its robust spread (NMAD), and the cloud's objects at the automatic
tolerance with and without the raised-class check.
ORTHO names the class-map files to read (default "ortho": ortho_<name>.json; "ortho_r0.33":
the raised-class check's, ORTHO_RAISED=0.33).
"""
import glob
import json
import os
import sys


def load(path):
    with open(path) as f:
        return json.load(f)


def pct(v):
    return "—" if v is None else "%.1f" % (100 * v)


def main():
    root = sys.argv[1]
    ortho = sys.argv[2] if len(sys.argv) > 2 else "ortho"
    rows, gaps, goals = [], [], []
    for metrics in sorted(glob.glob(os.path.join(root, "*", "results", "metrics_*.json"))):
        results = os.path.dirname(metrics)
        folder = os.path.basename(os.path.dirname(results))
        name = os.path.basename(metrics)[len("metrics_"):-len(".json")]
        labelled = ""
        if "_l" in folder.rsplit("_pl", 1)[-1]:  # LABELLED=...: <scene>..._l<labelled>
            folder, labelled = folder.rsplit("_l", 1)
        capture = "grid-oblique" if folder.endswith("_grid-oblique") else "orbit"
        scene = folder.replace("_grid-oblique", "").replace("_pl", "")
        if labelled:
            scene += " (labelled %s)" % labelled
        method = {"none": "Net-1", "full": "full"}.get(name, name)
        m = load(metrics)
        o = load(os.path.join(results, "%s_%s.json" % (ortho, name)))
        t = load(os.path.join(results, "3d_%s.json" % name))
        dsm = o["dsm"]["per_class"]
        building = o["area"].get("building")
        on1 = [s for s in t.get("on_surface", []) if s["max_gap_m"] == 1.0]
        if "miou_within" in o:
            near = {w["radius_share"]: w["miou"] for w in o["miou_within"]}
            ground = [c for c in ("road", "paved", "grass") if c in dsm and dsm[c].get("cells")]

            def off(c):
                return "%.2f / %.2f" % (dsm[c]["off_step_rmse_m"], dsm[c]["nmad_m"])
            spacing = {s.get("spacing_factor"): s for s in t.get("objects_by_spacing", [])}
            k4 = spacing.get(4.0)
            gaps.append((scene, capture, method, [
                pct(m["miou"]),
                "%s / %s / %s" % (pct(o["miou"]), pct(near.get(0.7)), pct(near.get(0.5))),
                off("building") if "building" in dsm else "—",
                " · ".join("%s %s" % (c, off(c)) for c in ground),
                "%.2f / %.2f" % (k4["f1"], k4["f1_raised_check"]) if k4 else "—",
            ]))
        if method == "full":
            goals.append((scene, capture, method, goal_cells(m, o, t)))
        rows.append((scene, capture, method, [
            "%d" % m["num_gaussians"],
            pct(m["miou"]),
            pct(t["point_miou"]),
            "%s / %.1f" % (pct(t["share_within_0.5_m"]), t["distance_p90_m"]),
            "%s (%+.1f)" % (pct(o["miou"]), 100 * (o["miou"] - m["miou"])),
            "%.2f / %.2f / %.2f" % (o["dsm"]["rmse_m"],
                                    dsm["building"]["rmse_m"] if "building" in dsm else float("nan"),
                                    dsm["road"]["rmse_m"]),
            "%+.0f %%" % (100 * building["relative_error"]) if building else "—",
            "%.2f / %.2f" % (o["objects"]["f1"], t["objects"]["f1"]) if "objects" in t else "—",
            "%s (%d %%)" % (pct(on1[0]["share_within_0.5_m"]),
                            round(100 * on1[0]["gaussians"] / t["gaussians"])) if on1 else "—",
        ]))
    order = {"Net-1": 0, "full": 1}
    print_table(rows, order, [
        "Gaussians", "view mIoU", "3D point mIoU", "opaque within 0.5 m / p90 (m)",
        "class map mIoU (− views)", "DSM RMSE all / roofs / road (m)", "building area",
        "building F1 map / cloud", "checked cloud (M = 1 m): within 0.5 m (kept)"],
        "---:|---:|---:|---|---|---|---:|---|---")
    if gaps:
        print()
        print_table(gaps, order, [
            "view mIoU", "class map mIoU: all / within 0.7 / within 0.5 of the half-width",
            "DSM roofs off the steps: RMSE / NMAD (m)", "ground off the steps: RMSE / NMAD (m)",
            "cloud building F1 at 4 x spacing: plain / checked"], "---:|---|---|---|---")
    if goals:
        print()
        print_table(goals, order, GOALS, "---|---|---|---|---|---|---")
        met = [sum(1 for g in goals if g[3][i].endswith("ok")) for i in range(len(GOALS))]
        known = [sum(1 for g in goals if g[3][i] != "—") for i in range(len(GOALS))]
        print()
        print("met: " + "; ".join("%s %d of %d" % (name, met[i], known[i])
                                  for i, name in enumerate(GOALS)))


GOALS = ["class map − views ≥ −5", "building area within ±10 %", "DSM roofs ≤ 2 × cell (m)",
         "DSM worst ground class ≤ 2 × cell (m)", "3D point mIoU ≥ views − 5",
         "opaque within 0.5 m ≥ 90 %", "map building F1 ≥ 0.8"]


def goal(text, ok):
    return "%s ok" % text if ok else text


def goal_cells(m, o, t):
    """One full run's value against each of GOALS: 'VALUE ok' where met, '—' where not scored."""
    dsm = o["dsm"]["per_class"]
    limit = 2 * o["gsd"]
    raised = set(o.get("raised_classes", []))
    ground = [(dsm[c]["rmse_m"], c) for c in dsm
              if c not in raised and c != "water" and dsm[c].get("cells")]
    building = o["area"].get("building")
    gap = 100 * (o["miou"] - m["miou"])
    cells = [goal("%+.1f" % gap, gap >= -5)]
    if building and building["relative_error"] is not None:
        e = 100 * building["relative_error"]
        cells.append(goal("%+.0f %%" % e, abs(e) <= 10))
    else:
        cells.append("—")
    if "building" in dsm and dsm["building"].get("cells"):
        r = dsm["building"]["rmse_m"]
        cells.append(goal("%.2f" % r, r <= limit))
    else:
        cells.append("—")
    if ground:
        r, c = max(ground)
        cells.append(goal("%.2f (%s)" % (r, c), r <= limit))
    else:
        cells.append("—")
    d = 100 * (t["point_miou"] - m["miou"])
    cells.append(goal("%+.1f" % d, d >= -5))
    w = 100 * t["share_within_0.5_m"]
    cells.append(goal("%.1f %%" % w, w >= 90))
    if "objects" in o:
        f = o["objects"]["f1"]
        cells.append(goal("%.2f" % f, f >= 0.8))
    else:
        cells.append("—")
    return cells


def print_table(rows, order, columns, align):
    """A Markdown table: scene, capture and run, then `columns` aligned as `align`."""
    rows.sort(key=lambda r: (r[0], r[1] != "orbit", order.get(r[2], 9)))
    print("| scene | capture | run | %s |" % " | ".join(columns))
    print("|---|---|---|%s|" % align)
    for scene, capture, method, cells in rows:
        print("| %s | %s | %s | %s |" % (scene, capture, method, " | ".join(cells)))


if __name__ == "__main__":
    main()
