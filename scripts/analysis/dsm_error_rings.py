#!/usr/bin/env python3
"""Where a DSM's error lies: the rendered DSM (`sadsplat ortho RUN --gsd 0.25 --bounds
-100,-100,100,100`) against a synth scene's true DSM (`truth_dsm.tif` from `sadsplat synth --out`),
by distance from the scene's centre (rings of the labelled area, Chebyshev distance in metres).

  python3 scripts/analysis/dsm_error_rings.py ORTHO_DIR/dsm.tif SCENE_DIR/truth_dsm.tif

Needs Debian's python3-gdal and python3-numpy. Both rasters on the same 0.25 m grid over
[-100, 100]^2 (a one-tile synth world); nodata -9999.
"""
import sys

import numpy as np
from osgeo import gdal


def main(dsm_path, truth_path):
    d = gdal.Open(dsm_path).ReadAsArray()
    t = gdal.Open(truth_path).ReadAsArray()
    if d.shape != t.shape:
        sys.exit("%s is %s, %s is %s: not one grid" % (dsm_path, d.shape, truth_path, t.shape))
    n = d.shape[0]
    gsd = 200.0 / n
    y, x = np.mgrid[0:n, 0:n]
    r = np.maximum(abs(-100 + (x + 0.5) * gsd), abs(100 - (y + 0.5) * gsd))
    m = (d != -9999) & (t != -9999)
    e = d - t
    total = (e[m] ** 2).sum()
    print("all: covered %.0f %%, rmse %.2f m, median |error| %.2f m"
          % (100 * m.mean(), np.sqrt((e[m] ** 2).mean()), np.median(abs(e[m]))))
    for lo, hi in ((0, 50), (50, 70), (70, 85), (85, 100)):
        ring = (r >= lo) & (r < hi)
        mm = m & ring
        if not mm.any():
            continue
        print("ring %3d-%3d m: covered %3.0f %%, rmse %6.2f m, median |error| %5.2f m, "
              "share of the squared error %3.0f %%"
              % (lo, hi, 100 * mm.sum() / ring.sum(), np.sqrt((e[mm] ** 2).mean()),
                 np.median(abs(e[mm])), 100 * (e[mm] ** 2).sum() / total))


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
