#pragma once
/// \file graph_segmentation.h
/// \brief Graph-based segmentation (Felzenszwalb & Huttenlocher 2004), the built-in backend's
/// other mask generator: pixels are nodes, 8-neighbour edges weighted by the CIELab distance of
/// the lightly smoothed image; edges are visited by increasing weight and two components merge
/// when the edge is no heavier than either component's largest internal edge plus k / size.
/// Homogeneous areas (a road, a field, a roof) become one large target, textured ones many small
/// ones — unlike SLIC's equal-size superpixels. Plain C++ (no OpenCV).

#include "sadsplat/io/scene.h"
#include "sadsplat/pseudo_labels/superpixels.h"

namespace sadsplat {
namespace pseudo_labels {

/// \brief Parameters of the graph segmentation.
struct GraphSegmentationOptions {
  double k = 300.0;    ///< scale of the merge threshold k / |C| (CIELab units x pixels)
  int min_size = 64;   ///< components smaller than this are merged into a neighbour
  double sigma = 0.8;  ///< Gaussian smoothing before the edge weights (pixels; 0: none)
};

/// \brief Segments an RGB image; pixels whose mask is 0 belong to no region. Regions are
/// numbered in order of their first pixel (row-major) and are 8-connected.
/// \throws sadsplat::Error on mismatched sizes or options out of range
Segmentation graphSegmentation(const io::Image8& rgb, const io::Image8& mask,
                               const GraphSegmentationOptions& options = {});

}  // namespace pseudo_labels
}  // namespace sadsplat
