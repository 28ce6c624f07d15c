#!/usr/bin/env python3
"""Scores of the test views that straddle block borders against those inside one block.

    python3 scripts/block_borders.py BLOCK_RUN [OTHER_RUN ...] [--straddle 0.8]

BLOCK_RUN is a run trained with `sadsplat train --blocks N` and evaluated (`sadsplat eval`):
its blocks.json gives, per view, the share of the sparse points it sees in each block's cell; a
view straddles a border when no cell holds `--straddle` (default 0.8) of them. Every run given
(e.g. one trained without blocks on the same scene) is scored on the same two groups of views,
from its metrics.json's per_view: mean PSNR and mean pixel accuracy.
"""
import argparse
import json
import math
import os
import sys


def load(path):
    with open(path) as f:
        return json.load(f)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("block_run")
    ap.add_argument("other_runs", nargs="*")
    ap.add_argument("--straddle", type=float, default=0.8)
    a = ap.parse_args()
    blocks = load(os.path.join(a.block_run, "blocks.json"))
    straddles = {}
    for v in blocks["views"]:
        shares = v["cell_shares"]
        if shares:
            straddles[v["name"]] = max(shares) < a.straddle
    print("%-40s %-9s %5s %8s %9s" % ("run", "views", "count", "PSNR", "accuracy"))
    for run in [a.block_run] + a.other_runs:
        metrics_path = os.path.join(run, "metrics.json")
        if not os.path.exists(metrics_path):
            sys.exit("%s: no metrics.json (run `sadsplat eval %s` first)" % (run, run))
        per_view = load(metrics_path).get("per_view")
        if per_view is None:
            sys.exit("%s: metrics.json has no per_view (evaluate it again)" % metrics_path)
        for group, wanted in (("inside", False), ("straddle", True)):
            views = [v for v in per_view if straddles.get(v["name"]) == wanted]
            psnr = sum(v["psnr"] for v in views) / len(views) if views else math.nan
            acc = [v["accuracy"] for v in views if v["accuracy"] is not None]
            accuracy = 100 * sum(acc) / len(acc) if acc else math.nan
            print("%-40s %-9s %5d %8.2f %8.2f%%" % (run[-40:], group, len(views), psnr, accuracy))


if __name__ == "__main__":
    main()
