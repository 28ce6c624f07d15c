#pragma once
/// \file raster_files.h
/// \brief Raster outputs through GDAL: GeoTIFF (DEFLATE, tiled, with its grid and CRS, nodata,
/// a colour table for class maps) and PNG (8 or 16 bit). Written atomically (a temporary file in
/// the same directory, renamed over the target); GDAL's .aux.xml side files are not written.

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace sadsplat {
namespace geo {

/// \brief An image to write: pixel-major, bands interleaved.
struct Raster {
  enum class Type { kByte, kUInt16, kFloat32 };
  int width = 0, height = 0, bands = 1;
  Type type = Type::kByte;
  std::vector<std::uint8_t> bytes;   ///< kByte
  std::vector<std::uint16_t> words;  ///< kUInt16
  std::vector<float> floats;         ///< kFloat32
  std::optional<double> nodata;      ///< of every band
  /// Colour table of a 1-band byte raster (class maps): entry i = class i's colour.
  std::vector<std::array<std::uint8_t, 3>> palette;
  bool last_band_is_alpha = false;  ///< RGBA orthophotos

  static Raster bytesOf(int width, int height, int bands);
  static Raster floatsOf(int width, int height);
  /// \throws sadsplat::Error naming `path` when the buffer does not match the size
  void check(const std::string& path) const;
};

/// \brief Where a GeoTIFF sits: GDAL's geotransform (x0, gsd, 0, y0, 0, -gsd): the top-left
/// corner of pixel (0, 0) at (x0, y0), pixels gsd map units wide; and the CRS as WKT.
struct MapGrid {
  double x0 = 0, y0 = 0, gsd = 1;
  std::string wkt;
};

/// \brief Writes a GeoTIFF (`grid` null: no georeferencing, e.g. a per-view depth).
/// \throws sadsplat::Error naming the path (GDAL's message) when it cannot be written
void writeGeoTiff(const std::string& path, const Raster& raster, const MapGrid* grid);

/// \brief Writes a PNG (byte or 16-bit; a byte raster with a palette is written as palette PNG).
/// \throws sadsplat::Error naming the path when it cannot be written
void writePng(const std::string& path, const Raster& raster);

/// \brief Reads band 1 of an 8-bit raster (PNG, GeoTIFF, ...) as bytes (a 1-band Raster).
/// \throws sadsplat::Error naming the path when it cannot be read or is not 8-bit
Raster readByteRaster(const std::string& path);

/// \brief Width and height of an image file (its header only), or nothing when GDAL cannot open
/// it (or the build has no GDAL).
std::optional<std::array<int, 2>> imageFileSize(const std::string& path);

}  // namespace geo
}  // namespace sadsplat
