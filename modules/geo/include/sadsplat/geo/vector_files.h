#pragma once
/// \file vector_files.h
/// \brief Vector outputs through GDAL/OGR: the objects of a class map (geo/map_objects.h) as
/// polygons in a GeoPackage (GDALPolygonize; simplified with OGR's topology-preserving
/// Douglas-Peucker), in the map's CRS, with class, height and area attributes; and polygons
/// given as rings. Written atomically.

#include <array>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "sadsplat/geo/raster_files.h"

namespace sadsplat {
namespace geo {

struct ObjectPolygonOptions {
  double simplify = 0;  ///< tolerance in map units (0: the cell outlines as they are)
  double min_area = 0;  ///< polygons smaller than this (map units^2) are left out
  std::string layer = "classes";
};

/// \brief What a map object is (geo/map_objects.h): its class and a height.
struct MapObjectAttributes {
  int class_id = 0;
  double height = 0;  ///< e.g. the median of the surface model over its cells
  /// e.g. the median of the surface model above the ground model (NaN: unknown, a null field)
  double height_above_ground = std::numeric_limits<double>::quiet_NaN();
};

/// \brief Writes the objects of a map as polygons to a GeoPackage: `labels` (row-major,
/// `width` x `height` cells on `grid`; 0 = none, k = objects[k - 1]) polygonized, one layer,
/// fields object_id (k), class_id, class (`names[class_id]`), height_m, height_above_ground_m
/// (null where unknown) and area_m2 (the simplified polygon's area, map units^2). Returns the
/// number of polygons written. \throws sadsplat::Error naming `path` when it cannot be written (or
/// without GDAL), or when the labels do not fit the size or name an object not in `objects`
std::size_t writeObjectPolygons(const std::string& path, const std::vector<int>& labels, int width,
                                int height, const std::vector<MapObjectAttributes>& objects,
                                const MapGrid& grid, const std::vector<std::string>& names,
                                const ObjectPolygonOptions& options);

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
