#pragma once
/// \file vector_files.h
/// \brief Vector outputs through GDAL/OGR: the regions of a class map as polygons in a
/// GeoPackage (GDALPolygonize, 8-connected; simplified with OGR's topology-preserving
/// Douglas-Peucker), in the map's CRS, with class and area attributes. Written atomically.

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "sadsplat/geo/raster_files.h"

namespace sadsplat {
namespace geo {

struct ClassPolygonOptions {
  std::vector<int> classes;  ///< class ids whose regions are written
  double simplify = 0;       ///< tolerance in map units (0: the cell outlines as they are)
  double min_area = 0;       ///< polygons smaller than this (map units^2) are left out
  std::string layer = "classes";
};

/// \brief Writes the regions of `classes` (1-band byte raster of class ids on `grid`) whose id is
/// in options.classes as polygons to a GeoPackage: one layer, fields class_id (integer), class
/// (`names[class_id]`) and area_m2 (the simplified polygon's area, map units^2). Returns the
/// number of polygons written.
/// \throws sadsplat::Error naming `path` when it cannot be written (or without GDAL)
std::size_t writeClassPolygons(const std::string& path, const Raster& classes, const MapGrid& grid,
                               const std::vector<std::string>& names,
                               const ClassPolygonOptions& options);

/// \brief A polygon with an id, a class name and a height (e.g. a building's footprint).
struct LabelledPolygon {
  std::vector<std::array<double, 2>> ring;  ///< outer ring, not closed (first != last)
  int id = 0;
  std::string class_name;
  double height = 0;
};

/// \brief Writes `polygons` to a GeoPackage layer `layer` (fields id, class, height_m, area_m2)
/// in the CRS `wkt` (empty: none). Returns the number written.
/// \throws sadsplat::Error naming `path` when it cannot be written (or without GDAL)
std::size_t writeLabelledPolygons(const std::string& path, const std::string& layer,
                                  const std::string& wkt,
                                  const std::vector<LabelledPolygon>& polygons);

}  // namespace geo
}  // namespace sadsplat
