#pragma once
/// \file ortho_render.h
/// \brief Top-down orthographic renders of a trained model onto a north-up map grid: the true
/// orthophoto, the class map, the surface height and the class confidence, tile by tile (the
/// features of a large grid do not fit in memory at once).

#include <array>
#include <cstdint>
#include <optional>
#include <ostream>
#include <vector>

#include "sadsplat/gaussians/rasterizer.h"
#include "sadsplat/gaussians/trainer.h"
#include "sadsplat/geo/map_frame.h"

namespace sadsplat {
namespace pipeline {

/// \brief A north-up grid in a map frame: pixel (i, j) covers map x in [x0 + i gsd,
/// x0 + (i + 1) gsd] and y in [y0 - (j + 1) gsd, y0 - j gsd] (GDAL's geotransform).
struct OrthoGrid {
  geo::MapFrame frame;
  double x0 = 0, y0 = 0, gsd = 1;
  int width = 0, height = 0;
  double top = 0;  ///< local height of the camera plane (above every Gaussian)
};

/// \brief The grid over the model's ground footprint: the 1st to 99th percentile of its
/// Gaussians' centres (those of opacity >= 0.1) in map x and y, 2 % margin, corners snapped to
/// whole multiples of `gsd`. A georeferenced scene gets its UTM frame (fitted over that
/// footprint), any other its local-metres frame. `bounds` (x0, y0, x1, y1 in the frame's map
/// units) replaces the footprint.
/// \throws sadsplat::Error for gsd <= 0, a grid over 40,000 pixels a side or an empty model
OrthoGrid footprintGrid(const gaussians::Trainer& trainer, const io::Scene& scene, double gsd,
                        const std::optional<std::array<double, 4>>& bounds = std::nullopt);

/// \brief A camera plane above every Gaussian of the model in `frame`: its highest centre in
/// local up, + 1 unit.
double orthoTop(const gaussians::Trainer& trainer, const geo::MapFrame& frame);

/// \brief The orthographic camera of the grid's pixels [x_off, x_off + w) x [y_off, y_off + h).
gaussians::RasterCamera orthoCamera(const OrthoGrid& grid, int x_off, int y_off, int w, int h);

/// \brief What an orthographic render gives per pixel (row-major; `covered` says which pixels
/// the Gaussians cover: accumulated alpha >= 0.5; the others are nodata).
struct OrthoImages {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;      ///< 3 per pixel
  std::vector<std::uint8_t> covered;  ///< 1 = covered
  std::vector<std::uint8_t>
      classes;                    ///< class id, 255 = none (uncovered, or a model without classes)
  std::vector<float> elevation;      ///< map height of the rendered surface (expected depth)
  std::vector<float> confidence;  ///< Trainer::classCosines of the class (0 without classes)
};

/// \brief Renders the grid in tiles of `tile` pixels; progress lines on `progress` if not null.
OrthoImages renderOrtho(const gaussians::Trainer& trainer, const OrthoGrid& grid,
                        std::ostream* progress = nullptr, int tile = 1024);

}  // namespace pipeline
}  // namespace sadsplat
