#pragma once
/// \file tileset_writer.h
/// \brief A TileTree as a 3D Tiles 1.1 tileset: `tileset.json` and one `.glb` per tile
/// (io/gltf_splats.h: KHR_gaussian_splatting, SPZ-compressed by default, class ids as feature
/// IDs), refinement REPLACE, box bounding volumes in the tree's z-up frame, whose root
/// `transform` places it on Earth (the ENU frame of a georeference, in ECEF) or is absent for a
/// local tileset. The glTF extensions are declared through `3DTILES_content_gltf` (what CesiumJS
/// reads to take the content as Gaussian splats). The content of each tile is turned from the
/// z-up frame to glTF's y-up axes ((x, y, z) -> (x, z, -y)), which 3D Tiles clients turn back.

#include <Eigen/Core>
#include <array>
#include <optional>
#include <string>

#include "sadsplat/io/gltf_splats.h"
#include "sadsplat/tiles/tile_tree.h"

namespace sadsplat {
namespace tiles {

/// \brief Where the tileset sits and what its content holds.
struct TilesetOptions {
  /// column-major 4x4 from the tree's frame to ECEF; none: a local tileset (no transform)
  std::optional<std::array<double, 16>> root_transform;
  io::GltfSplatOptions content;  ///< SPZ or plain, SH degree, class names
  std::string extras_json = "{}";  ///< a JSON object written as tileset.json's extras
};

/// \brief The rotation from a z-up frame to glTF's y-up axes: (x, y, z) -> (x, z, -y).
Eigen::Matrix3d zUpToGltfAxes();

/// \brief What was written.
struct TilesetSummary {
  std::size_t tiles = 0;
  std::size_t leaves = 0;
  int depth = 0;
  std::size_t max_tile_splats = 0;
  std::size_t leaf_splats = 0;  ///< Gaussians in the leaves (the model's count)
  std::size_t bytes = 0;        ///< all files together
  double root_error = 0;
};

/// \brief Writes `dir`/tileset.json and `dir`/tiles/L_I.glb (each file atomically; the folder is
/// made when missing).
/// \throws sadsplat::Error when a file cannot be written
TilesetSummary writeTileset(const std::string& dir, const TileTree& tree,
                            const TilesetOptions& options);

}  // namespace tiles
}  // namespace sadsplat
