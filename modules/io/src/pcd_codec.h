#pragma once
// PCD files (PCL's point cloud format, version 0.7) read and written without pcl_io.
//
// PCL's own PCDReader is not a validator: fed a damaged file it can crash, allocate what the
// header claims, or accept a file whose fields do not match and print its warnings to stderr.
// This codec checks the whole header and the data size against the bytes present before it
// allocates anything, and fails with one sadsplat::Error naming the file and the field.
//
// Format (https://pointclouds.org/documentation/tutorials/pcd_file_format.html): header lines
// VERSION, FIELDS, SIZE, TYPE, COUNT, WIDTH, HEIGHT, VIEWPOINT, POINTS, DATA (`#` comments), then
// ascii (one point per line), binary (points x point_step bytes, row-major, little endian), or
// binary_compressed (uint32 compressed size, uint32 uncompressed size, LZF data whose
// uncompressed form stores each field's values for all points one field after the other).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sadsplat {
namespace io {
namespace pcd {

/// One FIELDS entry.
struct Field {
  std::string name;
  std::size_t size = 4;  // bytes per value: 1, 2, 4 or 8
  char type = 'F';       // I (signed), U (unsigned), F (floating point)
  std::size_t count = 1;
  std::size_t offset = 0;  // byte offset within a row of Table::data
};

/// A PCD file's content: the fields and the points as packed little-endian rows.
struct Table {
  std::vector<Field> fields;
  std::size_t point_step = 0;
  std::uint32_t width = 0;
  std::uint32_t height = 1;
  std::size_t points = 0;
  std::string data_kind;           // ascii, binary or binary_compressed
  std::vector<std::uint8_t> data;  // points x point_step bytes

  /// The field called `name`, or nullptr.
  const Field* find(const std::string& name) const;
};

/// Reads and validates a whole PCD file.
/// \throws sadsplat::Error naming the file and the header line or point that is wrong
Table read(const std::string& path);

/// Reads only the header (FIELDS etc.; `data` stays empty) and validates it.
Table readHeader(const std::string& path);

/// Writes `table` as a binary PCD (atomically).
void write(const std::string& path, const Table& table);

/// The value at `p` of a field's type, as a double (64-bit integers beyond 2^53 round).
double loadValue(const std::uint8_t* p, const Field& f);
/// Stores `v` at `p` in the field's type; false when it is not representable (an integer field
/// given a fraction, a non-finite value or one out of range).
bool storeValue(double v, const Field& f, std::uint8_t* p);

/// Decompresses LZF data (the codec PCL uses for binary_compressed) into exactly `out_size`
/// bytes. Returns false on malformed input (a reference before the start, output overrun, or a
/// result of another size).
bool lzfDecompress(const std::uint8_t* in, std::size_t in_size, std::uint8_t* out,
                   std::size_t out_size);

}  // namespace pcd
}  // namespace io
}  // namespace sadsplat
