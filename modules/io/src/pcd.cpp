#include "sadsplat/io/pcd.h"

#include <pcl/common/io.h>

#include <cmath>
#include <cstring>

#include "pcd_codec.h"
#include "sadsplat/common/error.h"
#include "sadsplat/io/gaussian_checks.h"

namespace sadsplat {
namespace io {
namespace {

// PCL's datatype codes as PCD SIZE/TYPE.
pcd::Field fieldOf(const pcl::PCLPointField& f) {
  pcd::Field out;
  out.name = f.name;
  out.count = f.count;
  out.offset = f.offset;
  switch (f.datatype) {
    case pcl::PCLPointField::INT8:
      out.size = 1;
      out.type = 'I';
      break;
    case pcl::PCLPointField::UINT8:
      out.size = 1;
      out.type = 'U';
      break;
    case pcl::PCLPointField::INT16:
      out.size = 2;
      out.type = 'I';
      break;
    case pcl::PCLPointField::UINT16:
      out.size = 2;
      out.type = 'U';
      break;
    case pcl::PCLPointField::INT32:
      out.size = 4;
      out.type = 'I';
      break;
    case pcl::PCLPointField::UINT32:
      out.size = 4;
      out.type = 'U';
      break;
    case pcl::PCLPointField::FLOAT64:
      out.size = 8;
      out.type = 'F';
      break;
    default:
      out.size = 4;
      out.type = 'F';
      break;
  }
  return out;
}

// The fields of PointT (offsets within the point struct), padding left out.
template <typename PointT>
std::vector<pcd::Field> pointFields() {
  std::vector<pcd::Field> fields;
  for (const auto& f : pcl::getFields<PointT>()) {
    if (f.name != "_") fields.push_back(fieldOf(f));
  }
  return fields;
}

template <typename PointT>
void saveTable(const std::string& path, const pcl::PointCloud<PointT>& cloud) {
  pcd::Table t;
  const std::vector<pcd::Field> in_point = pointFields<PointT>();
  for (pcd::Field f : in_point) {
    f.offset = t.point_step;
    t.point_step += f.size * f.count;
    t.fields.push_back(f);
  }
  t.points = cloud.size();
  t.width = cloud.width * cloud.height == cloud.size() ? cloud.width
                                                       : static_cast<std::uint32_t>(cloud.size());
  t.height = cloud.width * cloud.height == cloud.size() ? cloud.height : 1;
  if (t.points == 0) {
    t.width = 0;
    t.height = 1;
  }
  t.data.resize(t.points * t.point_step);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto* point = reinterpret_cast<const std::uint8_t*>(&cloud[i]);
    for (std::size_t k = 0; k < in_point.size(); ++k) {
      std::memcpy(t.data.data() + i * t.point_step + t.fields[k].offset, point + in_point[k].offset,
                  in_point[k].size * in_point[k].count);
    }
  }
  pcd::write(path, t);
}

// Fills a PointT cloud from a table, matching fields by name. `aliases` lets one point field
// accept another file field name (rgba <- rgb), copied bit for bit: PCL stores packed colour
// as a float "rgb" field whose bits are the colour.
template <typename PointT>
pcl::PointCloud<PointT> loadTable(const std::string& path, const pcd::Table& t,
                                  const std::vector<std::string>& required, bool finite_only) {
  struct Mapping {
    pcd::Field to;
    const pcd::Field* from = nullptr;
    bool raw_bits = false;
  };
  std::vector<Mapping> map;
  for (const pcd::Field& to : pointFields<PointT>()) {
    Mapping m{to, t.find(to.name), false};
    if (m.from == nullptr && to.name == "rgba") {
      m.from = t.find("rgb");
    }
    if (m.from == nullptr) {
      for (const std::string& r : required) {
        if (r == to.name) {
          throw Error(path, "field " + to.name, "present", "missing");
        }
      }
      continue;
    }
    if (m.from->count != to.count) {
      throw Error(path, "COUNT of field " + m.from->name, std::to_string(to.count),
                  std::to_string(m.from->count));
    }
    m.raw_bits = to.name == "rgba" && m.from->size == 4;
    map.push_back(m);
  }
  pcl::PointCloud<PointT> cloud;
  cloud.resize(t.points);
  cloud.width = t.width;
  cloud.height = t.height;
  cloud.is_dense = true;
  for (std::size_t i = 0; i < t.points; ++i) {
    auto* point = reinterpret_cast<std::uint8_t*>(&cloud[i]);
    const std::uint8_t* row = t.data.data() + i * t.point_step;
    for (const Mapping& m : map) {
      for (std::size_t k = 0; k < m.to.count; ++k) {
        const std::uint8_t* src = row + m.from->offset + k * m.from->size;
        std::uint8_t* dst = point + m.to.offset + k * m.to.size;
        if (m.raw_bits) {
          std::memcpy(dst, src, 4);
          continue;
        }
        double v = pcd::loadValue(src, *m.from);
        // A float field is checked as the float it becomes (an 8-byte 1e300 is +inf then);
        // infinite opacities of Gaussians are left to checkReadGaussians, which clamps them.
        if (m.to.type == 'F' && m.to.size == 4 && std::isfinite(v)) {
          const float f = static_cast<float>(v);
          if (!std::isfinite(f)) {
            throw Error(path, "point " + std::to_string(i) + " field " + m.from->name,
                        "a finite number within float range", std::to_string(v));
          }
        }
        if (!std::isfinite(v) && !(std::isinf(v) && m.to.name == "opacity")) {
          // NaN marks an invalid point in a semantic cloud (PCL's convention); infinity never.
          if (finite_only || m.to.type != 'F' || std::isinf(v)) {
            throw Error(path, "point " + std::to_string(i) + " field " + m.from->name,
                        "a finite number", std::to_string(v));
          }
          cloud.is_dense = false;
        }
        // A signed -1 in an unsigned label means "no class" (kUnlabelled has the same bits).
        if (m.to.type == 'U' && m.to.name == "label" && v == -1.0) v = 4294967295.0;
        if (!pcd::storeValue(v, m.to, dst)) {
          throw Error(path, "point " + std::to_string(i) + " field " + m.from->name,
                      std::string("a value that fits ") + (m.to.type == 'U' ? "an unsigned" : "a") +
                          " " + std::to_string(8 * m.to.size) + "-bit field",
                      std::to_string(v));
        }
      }
    }
  }
  return cloud;
}

}  // namespace

PcdContent pcdContent(const std::string& path) {
  const pcd::Table t = pcd::readHeader(path);
  const bool xyz = t.find("x") && t.find("y") && t.find("z");
  if (xyz && t.find("f_dc") && t.find("opacity") && t.find("scale") && t.find("rot")) {
    return PcdContent::kGaussians;
  }
  if (xyz && t.find("label") && (t.find("rgb") || t.find("rgba"))) return PcdContent::kSemantic;
  return PcdContent::kOther;
}

std::vector<std::string> pcdFieldNames(const std::string& path) {
  std::vector<std::string> names;
  for (const pcd::Field& f : pcd::readHeader(path).fields) names.push_back(f.name);
  return names;
}

void savePcd(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud) {
  checkWritableGaussians(path, cloud);
  saveTable(path, cloud);
}

void savePcd(const std::string& path, const pcl::PointCloud<pcl::PointXYZRGBL>& cloud) {
  saveTable(path, cloud);
}

pcl::PointCloud<GaussianPoint> loadGaussianPcd(const std::string& path) {
  auto cloud = loadTable<GaussianPoint>(path, pcd::read(path),
                                        {"x", "y", "z", "f_dc", "opacity", "scale", "rot"}, true);
  checkReadGaussians(path, cloud);
  return cloud;
}

pcl::PointCloud<pcl::PointXYZRGBL> loadSemanticPcd(const std::string& path) {
  return loadTable<pcl::PointXYZRGBL>(path, pcd::read(path), {"x", "y", "z", "rgba", "label"},
                                      false);
}

}  // namespace io
}  // namespace sadsplat
