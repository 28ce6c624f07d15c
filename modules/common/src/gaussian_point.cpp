// Explicit instantiations of the PCL algorithms sadsplat uses on GaussianPoint, the way PCL
// instantiates them for its own point types: users include the plain PCL headers (which,
// without PCL_NO_PRECOMPILE, declare but do not define the templates) and link this library.
#include "sadsplat/common/gaussian_point.h"

#include <cstring>

#include <pcl/filters/crop_box.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/filters/random_sample.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/search/kdtree.h>

#include <pcl/filters/impl/crop_box.hpp>
#include <pcl/filters/impl/extract_indices.hpp>
#include <pcl/filters/impl/filter.hpp>
#include <pcl/filters/impl/filter_indices.hpp>
#include <pcl/filters/impl/random_sample.hpp>
#include <pcl/filters/impl/voxel_grid.hpp>
#include <pcl/impl/pcl_base.hpp>
#include <pcl/kdtree/impl/kdtree_flann.hpp>
#include <pcl/search/impl/kdtree.hpp>
#include <pcl/search/impl/search.hpp>

namespace sadsplat {

GaussianPoint::GaussianPoint()
    : nx(0.f), ny(0.f), nz(0.f), opacity(0.f), log_alpha(0.f), confidence(0.f), label(kUnlabelled) {
  x = y = z = 0.f;
  data[3] = 1.f;
  for (float& v : f_dc) v = 0.f;
  for (float& v : f_rest) v = 0.f;
  for (float& v : scale) v = 0.f;
  rot[0] = 1.f;
  rot[1] = rot[2] = rot[3] = 0.f;
  for (float& v : feature) v = 0.f;
}

bool bitwiseEqual(const GaussianPoint& a, const GaussianPoint& b) {
  auto same = [](const void* x, const void* y, std::size_t bytes) {
    return std::memcmp(x, y, bytes) == 0;
  };
  return same(&a.x, &b.x, 3 * sizeof(float)) && same(&a.nx, &b.nx, sizeof(float)) &&
         same(&a.ny, &b.ny, sizeof(float)) && same(&a.nz, &b.nz, sizeof(float)) &&
         same(a.f_dc, b.f_dc, sizeof(a.f_dc)) && same(a.f_rest, b.f_rest, sizeof(a.f_rest)) &&
         same(&a.opacity, &b.opacity, sizeof(float)) && same(a.scale, b.scale, sizeof(a.scale)) &&
         same(a.rot, b.rot, sizeof(a.rot)) && same(a.feature, b.feature, sizeof(a.feature)) &&
         same(&a.log_alpha, &b.log_alpha, sizeof(float)) &&
         same(&a.confidence, &b.confidence, sizeof(float)) && a.label == b.label;
}

}  // namespace sadsplat

template class pcl::PCLBase<sadsplat::GaussianPoint>;
template class pcl::Filter<sadsplat::GaussianPoint>;
template class pcl::FilterIndices<sadsplat::GaussianPoint>;
template class pcl::KdTreeFLANN<sadsplat::GaussianPoint>;
template class pcl::search::Search<sadsplat::GaussianPoint>;
template class pcl::search::KdTree<sadsplat::GaussianPoint>;
template class pcl::VoxelGrid<sadsplat::GaussianPoint>;
template class pcl::ExtractIndices<sadsplat::GaussianPoint>;
template class pcl::RandomSample<sadsplat::GaussianPoint>;
template class pcl::CropBox<sadsplat::GaussianPoint>;
