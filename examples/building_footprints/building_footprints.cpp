// building_footprints: the objects of one class of a trained sadsplat model, with PCL.
//
//   building_footprints MODEL.ply|pcd CLASSES.json CLASS OUT_DIR [TOLERANCE_M|auto] [MIN_POINTS]
//                       [GROUND_CLASS]
//
// 1. read the semantic Gaussians (sadsplat::io::readGaussians),
// 2. keep one class (sadsplat::filters::ClassExtraction, a pcl::FilterIndices),
// 3. remove outliers (pcl::StatisticalOutlierRemoval on the centres),
// 4. split into objects (pcl::EuclideanClusterExtraction; the tolerance by default 4 x the
//    median distance between neighbouring centres, at least 1 m: a compact model samples its
//    roofs every 0.4-1.2 m, and a fixed 1 m splits its buildings into fragments; at most 3 m:
//    a drone mission's sparser roofs would otherwise join buildings across the streets),
// 5. write OUT_DIR/object_<id>.pcd (the object's Gaussians, every field) and OUT_DIR/objects.csv:
//    id, Gaussians, centroid, and the oriented bounding box (pcl::MomentOfInertiaEstimation);
// 6. with Open3D (sadsplat::interop): the ground plane of GROUND_CLASS (default road) by Open3D's
//    RANSAC plane segmentation, and each object's height above it (column height_m).
#include <pcl/common/centroid.h>
#include <pcl/common/io.h>
#include <pcl/features/moment_of_inertia_estimation.h>
#include <pcl/filters/extract_indices.h>
#include <pcl/filters/statistical_outlier_removal.h>
#include <pcl/search/kdtree.h>
#include <pcl/segmentation/extract_clusters.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>

#include "sadsplat/common/error.h"
#include "sadsplat/filters/class_extraction.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/scene.h"
#if WITH_OPEN3D
#include "sadsplat/interop/open3d_conversion.h"
#endif

using Gaussians = pcl::PointCloud<sadsplat::GaussianPoint>;

// The ground plane (a, b, c, d with c >= 0, |(a, b, c)| = 1) of one class, by Open3D's RANSAC;
// false without Open3D or when the class has too few Gaussians.
bool groundPlane(const std::shared_ptr<Gaussians>& all, const std::string& ground_class,
                 const std::vector<sadsplat::ClassInfo>& classes, Eigen::Vector4d* plane) {
#if WITH_OPEN3D
  sadsplat::filters::ClassExtraction<sadsplat::GaussianPoint> by_class;
  by_class.setClassName(ground_class, classes);
  by_class.setInputCloud(all);
  Gaussians ground;
  by_class.filter(ground);
  if (ground.size() < 10) return false;
  const auto legacy = sadsplat::interop::toOpen3d(ground).ToLegacy();
  const auto fit = legacy.SegmentPlane(0.2, 3, 500);
  *plane = std::get<0>(fit) / std::get<0>(fit).head<3>().norm();
  if (plane->z() < 0) *plane = -*plane;
  return true;
#else
  (void)all, (void)ground_class, (void)classes, (void)plane;
  return false;
#endif
}

int main(int argc, char** argv) {
  if (argc < 5) {
    std::cerr << "usage: building_footprints MODEL.ply CLASSES.json CLASS OUT_DIR "
                 "[TOLERANCE_M=auto] [MIN_POINTS=20] [GROUND_CLASS=road]\n";
    return 2;
  }
  const std::string model = argv[1], classes_json = argv[2], class_name = argv[3];
  const std::filesystem::path out_dir = argv[4];
  const std::string tolerance_arg = argc > 5 ? argv[5] : "auto";
  const int min_points = argc > 6 ? std::stoi(argv[6]) : 20;
  const std::string ground_class = argc > 7 ? argv[7] : "road";
  try {
    // 1-2: the Gaussians of one class.
    auto all = std::make_shared<Gaussians>(sadsplat::io::readGaussians(model));
    sadsplat::filters::ClassExtraction<sadsplat::GaussianPoint> by_class;
    const auto classes = sadsplat::io::readClassesJson(classes_json);
    by_class.setClassName(class_name, classes);
    by_class.setInputCloud(all);
    auto of_class = std::make_shared<Gaussians>();
    by_class.filter(*of_class);

    // 3: outliers, judged on the centres.
    auto centres = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
    pcl::copyPointCloud(*of_class, *centres);
    pcl::StatisticalOutlierRemoval<pcl::PointXYZ> outliers;
    outliers.setInputCloud(centres);
    outliers.setMeanK(8);
    outliers.setStddevMulThresh(2.0);
    auto inliers = std::make_shared<pcl::Indices>();
    outliers.filter(*inliers);

    // 4: objects.
    auto tree = std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>();
    tree->setInputCloud(centres, inliers);
    double tolerance = 0;
    if (tolerance_arg == "auto") {
      std::vector<float> nearest;
      pcl::Indices found(2);
      std::vector<float> d2(2);
      for (const auto i : *inliers) {
        if (tree->nearestKSearch((*centres)[i], 2, found, d2) == 2)
          nearest.push_back(std::sqrt(d2[1]));
      }
      double spacing = 0;
      if (!nearest.empty()) {
        std::nth_element(nearest.begin(), nearest.begin() + nearest.size() / 2, nearest.end());
        spacing = nearest[nearest.size() / 2];
      }
      // As sadsplat's eval::autoClusterTolerance (metres).
      tolerance = std::min(3.0, std::max(1.0, 4 * spacing));
      std::cout << "cluster tolerance " << tolerance << " (4 x the median spacing " << spacing
                << ", at least 1, at most 3)\n";
    } else {
      std::size_t used = 0;
      try {
        tolerance = std::stod(tolerance_arg, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != tolerance_arg.size() || !(tolerance > 0)) {
        std::cerr << "building_footprints: error: TOLERANCE_M: expected a positive number of "
                     "metres or auto, got "
                  << tolerance_arg << "\n";
        return 1;
      }
    }
    std::vector<pcl::PointIndices> objects;
    pcl::EuclideanClusterExtraction<pcl::PointXYZ> clusters;
    clusters.setInputCloud(centres);
    clusters.setIndices(inliers);
    clusters.setSearchMethod(tree);
    clusters.setClusterTolerance(tolerance);
    clusters.setMinClusterSize(min_points);
    clusters.extract(objects);

    // 6 (first: the table has the column): the ground plane.
    Eigen::Vector4d plane;
    const bool have_ground = groundPlane(all, ground_class, classes, &plane);

    // 5: one PCD of Gaussians per object, and the table.
    std::filesystem::create_directories(out_dir);
    std::ofstream csv(out_dir / "objects.csv");
    csv << "id,gaussians,centroid_x,centroid_y,centroid_z,obb_x,obb_y,obb_z,obb_size_x,"
           "obb_size_y,obb_size_z,obb_qw,obb_qx,obb_qy,obb_qz"
        << (have_ground ? ",height_m" : "") << "\n";
    for (std::size_t id = 0; id < objects.size(); ++id) {
      auto indices = std::make_shared<pcl::PointIndices>(objects[id]);
      Gaussians object;
      pcl::ExtractIndices<sadsplat::GaussianPoint> take;
      take.setInputCloud(of_class);
      take.setIndices(indices);
      take.filter(object);
      char name[32];
      std::snprintf(name, sizeof(name), "object_%03zu.pcd", id);
      sadsplat::io::writeGaussians((out_dir / name).string(), object);

      Eigen::Vector4f centroid;
      pcl::compute3DCentroid(*centres, objects[id].indices, centroid);
      pcl::MomentOfInertiaEstimation<pcl::PointXYZ> moments;
      moments.setInputCloud(centres);
      moments.setIndices(indices);
      moments.compute();
      pcl::PointXYZ lo, hi, position;
      Eigen::Matrix3f rotation;
      moments.getOBB(lo, hi, position, rotation);
      const Eigen::Quaternionf q(rotation);
      csv << id << "," << object.size() << "," << centroid.x() << "," << centroid.y() << ","
          << centroid.z() << "," << position.x << "," << position.y << "," << position.z << ","
          << hi.x - lo.x << "," << hi.y - lo.y << "," << hi.z - lo.z << "," << q.w() << "," << q.x()
          << "," << q.y() << "," << q.z();
      if (have_ground) {  // the highest centre of the object above the ground plane
        double top = -1e30;
        for (const auto& p : object) {
          top = std::max(top, plane.dot(Eigen::Vector4d(p.x, p.y, p.z, 1.0)));
        }
        csv << "," << top;
      }
      csv << "\n";
    }
    std::cout << class_name << ": " << of_class->size() << " of " << all->size() << " Gaussians, "
              << inliers->size() << " after outlier removal, " << objects.size() << " objects -> "
              << (out_dir / "objects.csv").string() << "\n";
    if (have_ground) {
      std::cout << "ground plane of " << ground_class << " (Open3D RANSAC): " << plane.transpose()
                << "\n";
    }
  } catch (const sadsplat::Error& e) {
    std::cerr << "building_footprints: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
