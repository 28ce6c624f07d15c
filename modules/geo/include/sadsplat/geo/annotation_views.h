#pragma once
/// \file annotation_views.h
/// \brief Which photos to annotate: the few training views that together see most of the scene.
///
/// A class that no annotated photo shows cannot be learnt, and a user annotates three or so
/// photos. Picked by index, a drone mission's first photos lie on its first flight lines and see
/// a strip of the area. This choice is geometric only (it never looks at classes): the ground
/// plane (geo::sceneUp) over the sparse points' 1st to 99th percentiles is cut into square cells,
/// a cell is part of the footprint when a sparse point lies in it, a view sees a cell when one of
/// its points projects into the view's image in front of it (no occlusion test: the scene keeps
/// no tracks), and views are picked greedily, each the one that sees the most footprint cells
/// the views before it do not (ties: the lower view index). Already labelled training views
/// can be taken as picked first, so that the choice adds to them.

#include <string>
#include <vector>

#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace geo {

/// \brief How the views are chosen.
struct AnnotationViewOptions {
  int count = 3;   ///< views to pick (fewer when fewer candidates add anything)
  int cells = 48;  ///< footprint cells along the ground's longer side
  /// Take the scene's labelled training views as already picked and pick `count` more.
  bool keep_labelled = false;
  /// \throws sadsplat::Error naming `origin` and the field when a value is out of range
  void check(const std::string& origin) const;
};

/// \brief The choice and how much of the footprint it sees.
struct AnnotationViews {
  std::vector<int> kept;    ///< labelled views taken as picked (keep_labelled), scene order
  std::vector<int> picked;  ///< indices into scene.views, in the order they were picked
  /// Per picked view: the share of the footprint seen by the kept views and the views picked up
  /// to and including it.
  std::vector<double> cumulative_share;
  std::vector<double> own_share;  ///< per picked view: the share it sees alone
  double kept_share = 0;          ///< the share the kept views see
  double all_share = 0;           ///< the share all training views together see
  int footprint_cells = 0;        ///< cells holding a sparse point
  double cell_size = 0;           ///< side of a cell in scene units
};

/// \brief Chooses the training views (view.train, not test) to annotate.
/// \throws sadsplat::Error naming `origin` for a scene without sparse points or training views
AnnotationViews chooseAnnotationViews(const io::Scene& scene, const AnnotationViewOptions& options,
                                      const std::string& origin);

}  // namespace geo
}  // namespace sadsplat
