#include "sadsplat/io/cloud_files.h"

#include "sadsplat/common/error.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/gaussian_ply.h"
#include "sadsplat/io/pcd.h"
#include "sadsplat/io/semantic_ply.h"
#include "sadsplat/io/splat_formats.h"

namespace sadsplat {
namespace io {
namespace {

[[noreturn]] void unknownExtension(const std::string& path, const std::string& kind) {
  throw Error(path, "file name",
              "a " + kind + " file ending in .ply or .pcd" +
                  (kind == "Gaussian cloud" ? std::string(" (or .splat, .spz)") : std::string()),
              lowerExtension(path).empty() ? "no extension" : lowerExtension(path));
}

}  // namespace

CloudKind cloudKind(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext == ".splat" || ext == ".spz") {
    requireRegularFile(path);
    return CloudKind::kGaussians;
  }
  if (ext == ".ply") return isSemanticPly(path) ? CloudKind::kSemantic : CloudKind::kGaussians;
  if (ext == ".pcd") {
    switch (pcdContent(path)) {
      case PcdContent::kGaussians:
        return CloudKind::kGaussians;
      case PcdContent::kSemantic:
        return CloudKind::kSemantic;
      case PcdContent::kOther:
        throw Error(path, "FIELDS",
                    "GaussianPoint fields (x y z f_dc opacity scale rot ...) or a semantic cloud "
                    "(x y z rgb|rgba label)",
                    "neither");
    }
  }
  unknownExtension(path, "point cloud");
}

pcl::PointCloud<GaussianPoint> readGaussians(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext == ".ply") return readGaussianPly(path);
  if (ext == ".pcd") return loadGaussianPcd(path);
  if (ext == ".splat") return readSplat(path);
  if (ext == ".spz") return readSpz(path);
  unknownExtension(path, "Gaussian cloud");
}

void writeGaussians(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud) {
  const std::string ext = lowerExtension(path);
  if (ext == ".ply") {
    writeGaussianPly(path, cloud);
  } else if (ext == ".pcd") {
    savePcd(path, cloud);
  } else if (ext == ".splat") {
    writeSplat(path, cloud);
  } else if (ext == ".spz") {
    writeSpz(path, cloud);
  } else {
    unknownExtension(path, "Gaussian cloud");
  }
}

pcl::PointCloud<pcl::PointXYZRGBL> readSemanticCloud(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext == ".ply") return readSemanticPly(path);
  if (ext == ".pcd") return loadSemanticPcd(path);
  unknownExtension(path, "semantic cloud");
}

void writeSemanticCloud(const std::string& path, const pcl::PointCloud<pcl::PointXYZRGBL>& cloud) {
  const std::string ext = lowerExtension(path);
  if (ext == ".ply") {
    writeSemanticPly(path, cloud);
  } else if (ext == ".pcd") {
    savePcd(path, cloud);
  } else {
    unknownExtension(path, "semantic cloud");
  }
}

}  // namespace io
}  // namespace sadsplat
