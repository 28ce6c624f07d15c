#pragma once
// What `ortho` and `eval --ortho` share (internal to the pipeline): their render options checked
// and summarised, and the map's objects of a class (geo::mapObjects on the render).

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include <pcl/point_cloud.h>

#include "sadsplat/common/class_info.h"
#include "sadsplat/common/gaussian_point.h"
#include "sadsplat/geo/vector_files.h"
#include "sadsplat/pipeline/map_products.h"
#include "sadsplat/pipeline/ortho_render.h"

namespace sadsplat {
namespace pipeline {

// The render options `ortho` and `eval --ortho` share, checked before any file is read (errors
// name `what`, the command, and the flag); the cameras come with the scene.
OrthoRenderOptions checkedRenderOptions(const OrthoRunOptions& o, const char* what);

// The ids of class `names` among `classes`; an unknown name is an error naming `what` and
// `flag` and the model's classes.
std::vector<int> classIdsOf(const std::vector<std::string>& names,
                            const std::vector<ClassInfo>& classes, const char* what,
                            const char* flag);

// The classes OrthoRunOptions::trim names for a model with `classes` ("auto": building where
// there is one; "none" or empty: none).
std::vector<std::string> trimClasses(const OrthoRunOptions& o,
                                     const std::vector<ClassInfo>& classes);

// OrthoRunOptions::trim set on `render` for the run's model, and the Gaussians' classes from its
// training views (labelledCloud, returned for reuse) where the trim or `--class-from views` needs
// them; an empty cloud when neither does.
pcl::PointCloud<GaussianPoint> setGaussianClasses(OrthoRenderOptions& render,
                                                  const OrthoRunOptions& o,
                                                  const gaussians::Trainer& trainer,
                                                  const io::Scene& scene, const char* what);

// How the map was rendered (the surface, the class, the view checks) and what the raised-class
// check and the pit fill did (OrthoRenderOptions::raised_share, pit_depth), for ortho.json and
// ortho_metrics.json.
void addRenderOptions(nlohmann::json& j, const OrthoRunOptions& o, const OrthoImages& img,
                      const std::vector<ClassInfo>& classes);

// Map objects smaller than this merge into the neighbour of their class they border most (the
// slivers the height cut leaves along walls); also the smallest building the map scores.
constexpr double kMinObjectM2 = 20;
// kMinObjectM2 in cells of `gsd` map units (rounded up).
inline std::size_t minObjectCells(double gsd) {
  return static_cast<std::size_t>(std::ceil(kMinObjectM2 / (gsd * gsd)));
}

// The objects of each class in `wanted` on the map: its covered cells split where the surface
// model steps by more than `step` (geo::mapObjects), numbered across the classes, each with its
// class, the median height of its cells and, where the render has a ground model, their median
// height above it.
struct ClassObjects {
  std::vector<int> labels;
  std::vector<geo::MapObjectAttributes> objects;
};
ClassObjects classObjects(const OrthoImages& img, const std::vector<int>& wanted, double step,
                          std::size_t min_cells);

// The Gaussians of each map object, as `ortho --object-clouds` hands them out and `eval --ortho`
// scores them: those of `cloud` (a labelledCloud) labelled with the object's class, of opacity
// >= min_opacity, whose centre lies over one of the object's cells of `grid` (the objects'
// labels are on that grid). Indices into `cloud`, ascending; [k - 1] for object k. Grouping the
// cloud by the map's objects (cut where the DSM steps) instead of clustering it in 3D keeps
// neighbouring buildings apart (docs/measurements/cloud_3d).
// Opaque: the Gaussians whose centres make an object's footprint (eval --ortho's cloud_objects,
// the trim; `ortho --object-clouds` by default).
constexpr double kObjectMinOpacity = 0.5;

// OrthoRenderOptions::trim_classes: the cells of the objects of `classes` on the map (cut at
// `step`, slivers under `min_cells` merged) outside the convex hull of the centres of their
// Gaussians (objectGaussians at opacity 0.5, objects of at least kMinHullGaussians; a cell is
// outside when its centre is), and every cell of the objects with fewer than `whole_under`
// Gaussians over them. Ascending.
constexpr std::size_t kMinHullGaussians = 20;
std::vector<std::size_t> cellsOutsideObjectHulls(const pcl::PointCloud<GaussianPoint>& cloud,
                                                 const OrthoGrid& grid, const OrthoImages& img,
                                                 const std::vector<int>& classes, double step,
                                                 std::size_t min_cells, std::size_t whole_under);

std::vector<std::vector<std::size_t>> objectGaussians(const pcl::PointCloud<GaussianPoint>& cloud,
                                                      const OrthoGrid& grid,
                                                      const ClassObjects& objects,
                                                      double min_opacity);

}  // namespace pipeline
}  // namespace sadsplat
