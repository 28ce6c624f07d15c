#!/usr/bin/env python3
"""A DSM against a reference DSM of the same place (e.g. OpenDroneMap's of the same photos).

usage: dsm_against_reference.py OURS.tif REFERENCE.tif
Reads both with GDAL, warps OURS onto the reference's grid (bilinear, in the reference's CRS),
and prints, over the cells both cover: the median height difference (a datum offset: both
heights come from the photos' GPS altitudes in their own way), the RMSE and the median absolute
difference before and after removing that offset, and the shares within 0.5 / 1 / 2 m after it.
Needs python3-gdal and numpy (Debian: /usr/bin/python3).
"""
import sys

import numpy as np
from osgeo import gdal

gdal.UseExceptions()


def band(ds):
    b = ds.GetRasterBand(1)
    a = b.ReadAsArray().astype(np.float64)
    nodata = b.GetNoDataValue()
    valid = np.isfinite(a)
    if nodata is not None:
        valid &= a != nodata
    return a, valid


def main():
    ours_path, ref_path = sys.argv[1], sys.argv[2]
    ref = gdal.Open(ref_path)
    gt = ref.GetGeoTransform()
    w, h = ref.RasterXSize, ref.RasterYSize
    bounds = (gt[0], gt[3] + gt[5] * h, gt[0] + gt[1] * w, gt[3])
    warped = gdal.Warp("", ours_path, format="MEM", dstSRS=ref.GetProjection(),
                       outputBounds=bounds, width=w, height=h, resampleAlg="bilinear",
                       dstNodata=np.nan, outputType=gdal.GDT_Float64)
    a, va = band(warped)
    r, vr = band(ref)
    both = va & vr
    n = int(both.sum())
    print("cells: reference %d, ours %d, both %d (%.1f %% of the reference's)"
          % (vr.sum(), va.sum(), n, 100.0 * n / max(1, vr.sum())))
    if n == 0:
        return 1
    d = a[both] - r[both]
    offset = float(np.median(d))
    e = d - offset
    print("median difference (ours - reference): %.2f m" % offset)
    print("raw: RMSE %.2f m, median |d| %.2f m" % (np.sqrt(np.mean(d * d)), np.median(np.abs(d))))
    print("offset removed: RMSE %.2f m, median |d| %.2f m, p90 |d| %.2f m"
          % (np.sqrt(np.mean(e * e)), np.median(np.abs(e)), np.percentile(np.abs(e), 90)))
    print("within 0.5 / 1 / 2 m: %.1f / %.1f / %.1f %%"
          % tuple(100.0 * np.mean(np.abs(e) <= t) for t in (0.5, 1.0, 2.0)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
