#include "sadsplat/io/semantic_ply.h"

#include <cmath>
#include <cstdint>
#include <sstream>

#include "ply_codec.h"
#include "sadsplat/common/error.h"
#include "sadsplat/common/gaussian_point.h"
#include "sadsplat/io/atomic_file.h"

namespace sadsplat {
namespace io {
namespace {

const ply::PlyElement* findVertex(const ply::PlyHeader& header) {
  for (const auto& e : header.elements) {
    if (e.name == "vertex") return &e;
  }
  return nullptr;
}

bool hasProperty(const ply::PlyElement& e, const std::string& name) {
  for (const auto& p : e.properties) {
    if (p.name == name) return true;
  }
  return false;
}

}  // namespace

void writeSemanticPly(const std::string& path, const pcl::PointCloud<pcl::PointXYZRGBL>& cloud) {
  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\ncomment written by sadsplat: class colour "
            "and class id (-1: none) per point\nelement vertex "
         << cloud.size()
         << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
            "property uchar green\nproperty uchar blue\nproperty int label\nend_header\n";
  const std::string text = header.str();
  writeFileAtomically(path, [&](std::ostream& out) {
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    char record[19];
    for (const auto& p : cloud) {
      std::memcpy(record, &p.x, 4);
      std::memcpy(record + 4, &p.y, 4);
      std::memcpy(record + 8, &p.z, 4);
      record[12] = static_cast<char>(p.r);
      record[13] = static_cast<char>(p.g);
      record[14] = static_cast<char>(p.b);
      std::memcpy(record + 15, &p.label, 4);  // kUnlabelled's bits are -1 as an int
      out.write(record, sizeof(record));
    }
  });
}

namespace {

// A semantic PLY must have every property; a plain point PLY needs only x y z (colour defaults
// to grey, the label to none).
pcl::PointCloud<pcl::PointXYZRGBL> readPointPly(const std::string& path, bool semantic) {
  const std::string bytes = readWholeFile(path);
  const ply::PlyHeader header = ply::parseHeader(path, bytes);
  const ply::PlyElement* vertex = findVertex(header);
  if (vertex == nullptr) throw Error(path, "header", "an \"element vertex\" line", "none");
  const std::vector<const char*> required =
      semantic ? std::vector<const char*>{"x", "y", "z", "red", "green", "blue", "label"}
               : std::vector<const char*>{"x", "y", "z"};
  for (const char* name : required) {
    if (!hasProperty(*vertex, name)) {
      throw Error(path, std::string("vertex property ") + name,
                  semantic ? "present (a semantic PLY has x y z red green blue label)"
                           : "present (a point cloud has x y z)",
                  "missing");
    }
  }
  ply::ValueDecoder decoder(path, bytes, header.data_offset, header.format);
  for (const auto& e : header.elements) {
    if (&e == vertex) break;
    ply::skipElement(path, decoder, e, header.format);
  }
  ply::checkElementFits(path, decoder, *vertex, header.format);
  pcl::PointCloud<pcl::PointXYZRGBL> cloud;
  cloud.resize(vertex->count);
  cloud.is_dense = true;
  for (std::size_t i = 0; i < vertex->count; ++i) {
    auto& point = cloud[i];
    point.r = point.g = point.b = 128;
    point.label = kUnlabelled;
    for (const auto& p : vertex->properties) {
      const std::string what = "vertex " + std::to_string(i) + " property " + p.name;
      if (p.is_list) {
        throw Error(path, "vertex property " + p.name, "a scalar property", "a list");
      }
      const double v = decoder.next(p.type, what);
      if (p.name == "x" || p.name == "y" || p.name == "z") {
        const float f = static_cast<float>(v);
        // NaN marks an invalid point (PCL's convention for organised clouds); an infinite
        // coordinate, or one beyond float range, is a broken file.
        if (std::isinf(f)) {
          throw Error(path, what, "a finite coordinate (or NaN for an invalid point)",
                      std::to_string(v));
        }
        (p.name == "x" ? point.x : p.name == "y" ? point.y : point.z) = f;
        if (!std::isfinite(f)) cloud.is_dense = false;
      } else if (p.name == "red" || p.name == "green" || p.name == "blue") {
        if (!(v >= 0 && v <= 255) || v != std::floor(v)) {
          throw Error(path, what, "an integer colour in 0..255", std::to_string(v));
        }
        const auto c = static_cast<std::uint8_t>(v);
        (p.name == "red" ? point.r : p.name == "green" ? point.g : point.b) = c;
      } else if (p.name == "label") {
        if (v == -1.0) {
          point.label = kUnlabelled;
        } else if (v >= 0 && v < 4294967295.0 && v == std::floor(v)) {
          point.label = static_cast<std::uint32_t>(v);
        } else {
          throw Error(path, what, "a class id, or -1 for none", std::to_string(v));
        }
      }
    }
    decoder.endItem();
  }
  // Elements after the vertices are not used, but must be as complete as the header says.
  bool after = false;
  for (const auto& e : header.elements) {
    if (after) ply::skipElement(path, decoder, e, header.format);
    after = after || &e == vertex;
  }
  return cloud;
}

}  // namespace

pcl::PointCloud<pcl::PointXYZRGBL> readSemanticPly(const std::string& path) {
  return readPointPly(path, true);
}

pcl::PointCloud<pcl::PointXYZRGBL> readPointCloudPly(const std::string& path) {
  return readPointPly(path, false);
}

bool isSemanticPly(const std::string& path) {
  // Only the header (16 MiB is more than any real one): the vertices are not needed to tell.
  const std::string bytes = readFileStart(path, std::size_t{1} << 24);
  const ply::PlyHeader header = ply::parseHeader(path, bytes);
  const ply::PlyElement* vertex = findVertex(header);
  return vertex != nullptr && hasProperty(*vertex, "label") && hasProperty(*vertex, "red") &&
         !hasProperty(*vertex, "f_dc_0");
}

}  // namespace io
}  // namespace sadsplat
