#pragma once
/// \file las.h
/// \brief LAS 1.4 point clouds (ASPRS LAS Specification 1.4 R15), point data record format 7:
/// X, Y, Z as scaled 32-bit integers, RGB, the ASPRS classification, the CRS as OGC WKT in a
/// LASF_Projection VLR (record 2112). Debian ships no LAS library (no PDAL, no LAStools, no
/// laspy), so this is a small writer and a reader for exactly what it writes (and any other
/// uncompressed format 6/7 file); the tests check it byte by byte against the specification and
/// scripts/interop/las_check.sh reads it with an independent reader (loaders.gl's LAS loader).
/// Also: the ASPRS standard classes and the default class-name -> code mapping.

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace sadsplat {
namespace io {

/// \brief One LAS point: real coordinates (the file stores them scaled), 16-bit RGB.
struct LasPoint {
  double x = 0, y = 0, z = 0;
  std::array<std::uint16_t, 3> rgb{0, 0, 0};
  std::uint8_t classification = 0;  ///< ASPRS code (0 = never classified, 1 = unclassified, ...)
};

/// \brief What a LAS file says besides its points.
struct LasHeader {
  std::string wkt;  ///< the CRS (OGC WKT), empty = none
  std::array<double, 3> scale{0.001, 0.001, 0.001};
  std::array<double, 3> offset{0, 0, 0};
  std::array<double, 3> min{0, 0, 0}, max{0, 0, 0};  ///< of the points (filled by writeLas)
  std::string system_identifier = "sadsplat";
  std::string generating_software = "sadsplat";
  std::uint64_t point_count = 0;
  int point_format = 7;
  int version_minor = 4;
};

/// \brief Writes a LAS 1.4 file of format 7 (atomically). The offset is the points' minimum
/// rounded down to a whole metre and the scale `header.scale` (1 mm by default), so every point
/// fits the 32-bit integers with room; a cloud more than 2^31 scale units across is an error.
/// \throws sadsplat::Error naming the file (non-finite coordinates, a cloud too large, a WKT over
/// 65,000 characters, an unwritable path)
void writeLas(const std::string& path, const std::vector<LasPoint>& points, LasHeader header);

/// \brief Reads an uncompressed LAS 1.4 file of point format 6 or 7 (format 6 has no colour).
/// \throws sadsplat::Error naming the file and the field for anything else (LAZ, older versions,
/// a truncated file, counts that do not match the size)
std::vector<LasPoint> readLas(const std::string& path, LasHeader* header = nullptr);

/// \brief Reads a LAS file as readLas does, handing each point to `visit` instead of keeping
/// them (memory stays bounded whatever the file's size). The header is checked first (scale
/// factors in (0, 1000], finite offsets, finite bounds) and its bounds against the points at the
/// end (they must hold every point within a scale unit).
/// \returns the header
LasHeader forEachLasPoint(const std::string& path,
                          const std::function<void(const LasPoint&)>& visit);

/// \brief The ASPRS classes of LAS 1.4 (table 17): code -> name, for the codes sadsplat assigns.
const std::map<int, std::string>& asprsClassNames();

/// \brief Default ASPRS code of a semantic class, from its name (case-insensitive words):
/// ground / soil / bare / sand / earth / dirt -> 2 ground; grass / lawn / field / crop / low
/// vegetation -> 3; shrub / bush -> 4; tree / forest / vegetation -> 5 high vegetation; building /
/// roof / house -> 6; water / river / sea / lake / pond -> 9; rail -> 10; road / street /
/// asphalt / pavement / parking / path -> 11 road surface; bridge -> 17. Anything else gets a
/// user-definable code, 64 + its class id (LAS 1.4 reserves 64..255 for users).
int defaultAsprsCode(const std::string& class_name, int class_id);

/// \brief The code of every class: the defaults, overridden by a JSON file {"class name": code}
/// (`--classification-map`). Codes must be 0..255; names must be classes of the model.
/// \throws sadsplat::Error naming the file and the field
std::vector<int> asprsCodes(const std::vector<std::string>& class_names,
                            const std::string& mapping_json_path = "");

}  // namespace io
}  // namespace sadsplat
