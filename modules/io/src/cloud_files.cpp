#include "sadsplat/io/cloud_files.h"

#include <cctype>

#include "sadsplat/common/error.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/gaussian_ply.h"
#include "sadsplat/io/pcd.h"
#include "sadsplat/io/semantic_ply.h"
#include "sadsplat/io/gltf_splats.h"
#include "sadsplat/io/splat_formats.h"

namespace sadsplat {
namespace io {
namespace {

[[noreturn]] void unknownExtension(const std::string& path, const std::string& kind) {
  throw Error(path, "file name",
              "a " + kind + " file ending in .ply or .pcd" +
                  (kind == "Gaussian cloud" ? std::string(" (or .splat, .spz, .sog, .glb)")
                                            : std::string()),
              lowerExtension(path).empty() ? "no extension" : lowerExtension(path));
}

bool isCompressedPlyName(const std::string& path) {
  std::string lower = path;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return endsWith(lower, ".compressed.ply");
}

}  // namespace

CloudKind cloudKind(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext == ".splat" || ext == ".spz" || ext == ".sog" || ext == ".glb") {
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

pcl::PointCloud<GaussianPoint> readGaussians(const std::string& path,
                                             GaussianReadReport* report) {
  const std::string ext = lowerExtension(path);
  pcl::PointCloud<GaussianPoint> cloud;
  std::size_t clamped = 0;
  if (ext == ".ply" && isCompressedPly(path)) {
    CompressedPlyInfo info;
    cloud = readCompressedPly(path, &info);
    clamped = info.clamped_opacities;
  } else if (ext == ".ply") {
    PlyFileInfo info;
    cloud = readGaussianPly(path, &info);
    clamped = info.clamped_opacities;
  } else if (ext == ".pcd") {
    cloud = loadGaussianPcd(path);
  } else if (ext == ".splat") {
    cloud = readSplat(path);
  } else if (ext == ".spz") {
    SpzFileInfo info;
    cloud = readSpz(path, &info);
    clamped = info.clamped_opacities;
  } else if (ext == ".sog") {
    SogFileInfo info;
    cloud = readSog(path, &info);
    clamped = info.clamped_opacities;
  } else if (ext == ".glb") {
    cloud = readSplatGlb(path);  // glTF's y-up axes, as written
  } else {
    unknownExtension(path, "Gaussian cloud");
  }
  if (report != nullptr) report->clamped_opacities = clamped;
  return cloud;
}

void writeGaussians(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud) {
  const std::string ext = lowerExtension(path);
  if (isCompressedPlyName(path)) {
    throw Error(path, "file name",
                "an output sadsplat writes: .ply, .pcd, .splat, .spz or .sog (PlayCanvas' "
                ".compressed.ply is read only: write .ply and convert it with splat-transform)",
                "not supported: writing .compressed.ply");
  }
  if (ext == ".ply") {
    writeGaussianPly(path, cloud);
  } else if (ext == ".pcd") {
    savePcd(path, cloud);
  } else if (ext == ".splat") {
    writeSplat(path, cloud);
  } else if (ext == ".spz") {
    writeSpz(path, cloud);
  } else if (ext == ".sog") {
    writeSog(path, cloud);
  } else {
    unknownExtension(path, "Gaussian cloud");
  }
}

std::string convertCloudFile(const std::string& in, const std::string& out,
                             const ConvertOptions& options) {
  if (cloudKind(in) == CloudKind::kSemantic) {
    writeSemanticCloud(out, readSemanticCloud(in));
    return "";
  }
  GaussianReadReport report;
  SpzWriteOptions spz;
  spz.version = options.spz_version;
  pcl::PointCloud<GaussianPoint> cloud;
  if (lowerExtension(in) == ".spz") {
    SpzFileInfo info;
    cloud = readSpz(in, &info);
    report.clamped_opacities = info.clamped_opacities;
    spz.antialiased = info.antialiased;
  } else {
    cloud = readGaussians(in, &report);
  }
  if (lowerExtension(out) == ".spz") {
    writeSpz(out, cloud, spz);
  } else {
    writeGaussians(out, cloud);
  }
  if (report.clamped_opacities == 0) return "";
  return std::to_string(report.clamped_opacities) + " infinite opacities of " + in +
         " clamped to +-" + std::to_string(static_cast<int>(kMaxOpacityLogit));
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
