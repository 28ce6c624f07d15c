#include "sadsplat/common/semantic_cloud.h"

#include "sadsplat/common/error.h"

namespace sadsplat {

std::optional<std::uint32_t> findClass(const std::vector<ClassInfo>& classes,
                                       const std::string& name) {
  for (std::size_t i = 0; i < classes.size(); ++i) {
    if (classes[i].name == name) return static_cast<std::uint32_t>(i);
  }
  return std::nullopt;
}

pcl::PointCloud<pcl::PointXYZRGBL> toSemanticCloud(const pcl::PointCloud<GaussianPoint>& cloud,
                                                   const std::vector<ClassInfo>& classes) {
  pcl::PointCloud<pcl::PointXYZRGBL> out;
  out.header = cloud.header;
  out.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const GaussianPoint& g = cloud[i];
    pcl::PointXYZRGBL& p = out[i];
    p.x = g.x;
    p.y = g.y;
    p.z = g.z;
    p.label = g.label;
    if (g.label == kUnlabelled) {
      p.r = p.g = p.b = kUnlabelledGrey;
    } else if (g.label < classes.size()) {
      p.r = classes[g.label].color[0];
      p.g = classes[g.label].color[1];
      p.b = classes[g.label].color[2];
    } else {
      throw Error("<cloud>", "label of point " + std::to_string(i),
                  "a class id below " + std::to_string(classes.size()) + " or kUnlabelled",
                  std::to_string(g.label));
    }
    p.a = 255;
  }
  out.width = cloud.width;
  out.height = cloud.height;
  out.is_dense = cloud.is_dense;
  return out;
}

}  // namespace sadsplat
