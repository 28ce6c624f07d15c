#pragma once
// A small reader of ZIP archives held in memory (the container of PlayCanvas' .sog): the central
// directory, stored (method 0) and deflated (method 8) entries. No ZIP64, no encryption: such
// archives are refused by name. Sizes come from the central directory and are checked against
// the archive before anything is inflated.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace sadsplat {
namespace io {

class ZipArchive {
 public:
  /// Parses the central directory of `bytes` (the whole archive); `path` names it in errors.
  ZipArchive(std::string path, const std::string& bytes);

  /// Whether the archive has an entry called `name`.
  bool contains(const std::string& name) const;
  /// The uncompressed content of entry `name`, at most `max_bytes` long.
  /// \throws sadsplat::Error when it is missing, larger, corrupt or uses another method
  std::vector<std::uint8_t> read(const std::string& name, std::size_t max_bytes) const;

 private:
  struct Entry {
    std::string name;
    std::uint16_t method = 0;
    std::uint64_t compressed = 0;
    std::uint64_t uncompressed = 0;
    std::uint64_t local_offset = 0;
  };
  const Entry& find(const std::string& name) const;

  std::string path_;
  const std::string& bytes_;
  std::vector<Entry> entries_;
};

/// \brief A ZIP archive of `entries` (name, content) stored without compression (method 0, as
/// PlayCanvas' .sog writes its already compressed WebP images), with CRC-32s and a central
/// directory. No ZIP64: the archive must stay under 4 GiB.
/// \throws sadsplat::Error naming `path` when it would not
std::string storedZip(const std::string& path,
                      const std::vector<std::pair<std::string, std::string>>& entries);

}  // namespace io
}  // namespace sadsplat
