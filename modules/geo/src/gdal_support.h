#pragma once
// GDAL setup and handles shared by the raster and vector writers (only with SADSPLAT_HAVE_GDAL).

#include <cpl_conv.h>
#include <cpl_error.h>
#include <gdal_priv.h>

#include <memory>
#include <string>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace geo {
namespace gdal {

struct DatasetCloser {
  void operator()(GDALDataset* d) const { GDALClose(d); }
};
using Dataset = std::unique_ptr<GDALDataset, DatasetCloser>;

inline void init() {
  static const bool once = [] {
    GDALAllRegister();
    CPLSetConfigOption("GDAL_PAM_ENABLED", "NO");  // no .aux.xml side files
    // GDAL's (and, through it, PROJ's) messages are not printed: sadsplat's one-line error
    // carries the last of them (CPLGetLastErrorMsg), instead of 15 lines before it on a full disk.
    CPLSetErrorHandler(CPLQuietErrorHandler);
    return true;
  }();
  (void)once;
}

[[noreturn]] inline void failed(const std::string& path, const char* what) {
  throw Error(path, what, "a file GDAL can write (an existing, writable directory)",
              CPLGetLastErrorMsg()[0] ? CPLGetLastErrorMsg() : "GDAL failed");
}

}  // namespace gdal
}  // namespace geo
}  // namespace sadsplat
