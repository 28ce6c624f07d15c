#pragma once
/// \file world_truth.h
/// \brief The truth of a generated world as files other tools read (`sadsplat synth --out`):
/// its true surface model as a GeoTIFF, its buildings' footprints as a GeoPackage and the
/// samples of its top surface with class and instance as a PLY point cloud, all in the scene's
/// frame (local metres, z up). docs/formats.md describes them.

#include <string>

namespace sadsplat {
namespace pipeline {

/// \brief Writes DIR/truth_dsm.tif, DIR/truth_buildings.gpkg and DIR/truth_surface.ply for the
/// world named by `world_id` (synth::worldFromId). Returns a one-line summary.
/// \throws sadsplat::Error for an id that names no world, or files that cannot be written
std::string writeWorldTruth(const std::string& world_id, const std::string& dir);

}  // namespace pipeline
}  // namespace sadsplat
