#include "sadsplat/io/pcd.h"

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"

#if SADSPLAT_HAVE_PCL_IO
#include <pcl/io/pcd_io.h>
#endif

namespace sadsplat {
namespace io {
namespace {

[[noreturn, maybe_unused]] void noPcd(const std::string& path) {
  throw Error(path, "PCD", "a sadsplat build with pcl_io (SADSPLAT_WITH_VTK=ON)",
              "a build without it");
}

#if SADSPLAT_HAVE_PCL_IO
template <typename PointT>
void savePcdImpl(const std::string& path, const pcl::PointCloud<PointT>& cloud) {
  writeViaTemporaryPath(path, [&](const std::string& tmp) {
    pcl::PCDWriter writer;
    if (writer.writeBinary(tmp, cloud) != 0) {
      throw Error(path, "PCD write", "success", "pcl::PCDWriter failed");
    }
  });
}
#endif

}  // namespace

bool havePcdSupport() { return SADSPLAT_HAVE_PCL_IO != 0; }

void savePcd(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud) {
#if SADSPLAT_HAVE_PCL_IO
  savePcdImpl(path, cloud);
#else
  noPcd(path);
#endif
}

void savePcd(const std::string& path, const pcl::PointCloud<pcl::PointXYZRGBL>& cloud) {
#if SADSPLAT_HAVE_PCL_IO
  savePcdImpl(path, cloud);
#else
  noPcd(path);
#endif
}

pcl::PointCloud<GaussianPoint> loadGaussianPcd(const std::string& path) {
#if SADSPLAT_HAVE_PCL_IO
  pcl::PCLPointCloud2 blob;
  pcl::PCDReader reader;
  if (reader.read(path, blob) != 0) {
    throw Error(path, "PCD", "a readable PCD file", "pcl::PCDReader failed");
  }
  for (const char* required : {"x", "y", "z", "f_dc", "opacity", "scale", "rot"}) {
    bool found = false;
    for (const auto& f : blob.fields) found = found || f.name == required;
    if (!found) throw Error(path, std::string("field ") + required, "present", "missing");
  }
  pcl::PointCloud<GaussianPoint> cloud;
  pcl::fromPCLPointCloud2(blob, cloud);
  return cloud;
#else
  noPcd(path);
#endif
}

}  // namespace io
}  // namespace sadsplat
