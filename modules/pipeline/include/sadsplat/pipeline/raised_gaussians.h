#pragma once
/// \file raised_gaussians.h
/// \brief The class map's raised-class check (geo/ground_model.h) applied to the cloud: the
/// Gaussians of a raised class (buildings, trees) that lie at ground height.
///
/// A building Gaussian on the street between two buildings joins them into one object when the
/// building class is extracted and clustered (examples/building_footprints). The ground under the
/// model is estimated from its opaque Gaussians' centres (geo::groundUnderPoints: the highest
/// centre per 1 m cell as a surface model, then the DSM's ground rule), every labelled Gaussian's
/// height above it compared with its class's median (geo::findLowRaisedCells): a Gaussian of a
/// class whose median stands at least 2.5 units above the ground, lower than SHARE x that median,
/// is listed. Heights are in scene units: the thresholds are metres for georeferenced and synth
/// scenes, meaningless for an arbitrary SfM scale.

#include <pcl/point_cloud.h>

#include <ostream>
#include <string>
#include <vector>

#include "sadsplat/common/gaussian_point.h"
#include "sadsplat/geo/ground_model.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace pipeline {

/// \brief How the check runs.
struct RaisedGaussianOptions {
  double share = 0.33;         ///< listed below share x the class's median above the ground
  double window = 20.0;        ///< ground windows (scene units)
  double cell = 1.0;           ///< cells of the centres' surface model (scene units)
  double raised_height = 2.5;  ///< a class is raised at this median above the ground
  float opaque = 0.5f;         ///< Gaussians at least this opaque make the ground
  /// Nothing is listed when fewer of the labelled Gaussians lie within half the raised height
  /// of the ground (a broken ground). Lower than the map's bound (geo::kMinNearGround): a cloud
  /// holds its facades too.
  double min_near_ground = 0.15;
};

/// \brief Finds them; `cells` of the result are indices into `cloud`. The up direction is the
/// scene's (geo::sceneUp). Nothing is listed when share is 0.
/// \throws sadsplat::Error for a share outside [0, 1] or a bad cell / window
geo::LowRaisedCells findLowRaisedGaussians(const pcl::PointCloud<GaussianPoint>& cloud,
                                           const io::Scene& scene, int num_classes,
                                           const RaisedGaussianOptions& options = {});

/// \brief The run's model as written (`model`: its model.ply, labels as stored) without the
/// Gaussians findLowRaisedGaussians lists (the run's scene gives the up direction, its classes
/// their count): what `extract RUN --raised-check SHARE` starts from. `report`, when given, gets
/// a line saying how many went and which classes are raised.
/// \throws sadsplat::Error for a run that cannot be opened or a bad share
pcl::PointCloud<GaussianPoint> withoutLowRaisedGaussians(
    const std::string& run_dir, const pcl::PointCloud<GaussianPoint>& model,
    const RaisedGaussianOptions& options, std::ostream* report = nullptr);

}  // namespace pipeline
}  // namespace sadsplat
