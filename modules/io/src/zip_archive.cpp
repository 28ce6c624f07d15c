#include "zip_archive.h"

#include <algorithm>
#include <cstring>

#include <zlib.h>

#include "compression.h"
#include "sadsplat/common/error.h"

namespace sadsplat {
namespace io {
namespace {

constexpr std::uint32_t kEndOfDirectory = 0x06054b50;
constexpr std::uint32_t kDirectoryEntry = 0x02014b50;
constexpr std::uint32_t kLocalHeader = 0x04034b50;
constexpr std::size_t kEndRecordBytes = 22;
constexpr std::size_t kMaxCommentBytes = 65535;

template <typename T>
T load(const std::string& bytes, std::size_t offset) {
  T v;
  std::memcpy(&v, bytes.data() + offset, sizeof(T));
  return v;
}

}  // namespace

ZipArchive::ZipArchive(std::string path, const std::string& bytes)
    : path_(std::move(path)), bytes_(bytes) {
  if (bytes.size() < kEndRecordBytes || load<std::uint32_t>(bytes, 0) != kLocalHeader) {
    throw Error(path_, "archive", "a ZIP archive (starting \"PK\\x03\\x04\")", "other bytes");
  }
  // The end-of-directory record is the last 22 bytes plus an optional comment.
  std::size_t end = std::string::npos;
  const std::size_t lowest =
      bytes.size() > kEndRecordBytes + kMaxCommentBytes ? bytes.size() - kEndRecordBytes -
                                                              kMaxCommentBytes
                                                        : 0;
  for (std::size_t at = bytes.size() - kEndRecordBytes + 1; at-- > lowest;) {
    if (load<std::uint32_t>(bytes, at) == kEndOfDirectory) {
      end = at;
      break;
    }
  }
  if (end == std::string::npos) {
    throw Error(path_, "ZIP end of central directory", "present", "missing (truncated archive)");
  }
  const std::uint16_t count = load<std::uint16_t>(bytes, end + 10);
  const std::uint32_t directory_size = load<std::uint32_t>(bytes, end + 12);
  const std::uint32_t directory_offset = load<std::uint32_t>(bytes, end + 16);
  if (count == 0xffff || directory_offset == 0xffffffffu) {
    throw Error(path_, "ZIP directory", "a plain ZIP archive", "not supported: ZIP64");
  }
  if (static_cast<std::uint64_t>(directory_offset) + directory_size > end) {
    throw Error(path_, "ZIP directory offset", "inside the archive",
                std::to_string(directory_offset));
  }
  std::size_t at = directory_offset;
  for (std::uint16_t i = 0; i < count; ++i) {
    if (at + 46 > end || load<std::uint32_t>(bytes, at) != kDirectoryEntry) {
      throw Error(path_, "ZIP directory entry " + std::to_string(i), "a central directory entry",
                  "other bytes");
    }
    Entry e;
    const std::uint16_t flags = load<std::uint16_t>(bytes, at + 8);
    e.method = load<std::uint16_t>(bytes, at + 10);
    e.compressed = load<std::uint32_t>(bytes, at + 20);
    e.uncompressed = load<std::uint32_t>(bytes, at + 24);
    const std::uint16_t name_bytes = load<std::uint16_t>(bytes, at + 28);
    const std::uint16_t extra_bytes = load<std::uint16_t>(bytes, at + 30);
    const std::uint16_t comment_bytes = load<std::uint16_t>(bytes, at + 32);
    e.local_offset = load<std::uint32_t>(bytes, at + 42);
    if (at + 46 + name_bytes > end) {
      throw Error(path_, "ZIP directory entry " + std::to_string(i), "a name inside the archive",
                  "a name past its end");
    }
    e.name = bytes.substr(at + 46, name_bytes);
    if (flags & 1) throw Error(path_, "ZIP entry " + e.name, "an unencrypted entry", "encrypted");
    entries_.push_back(e);
    at += 46 + name_bytes + extra_bytes + comment_bytes;
  }
}

bool ZipArchive::contains(const std::string& name) const {
  return std::any_of(entries_.begin(), entries_.end(),
                     [&](const Entry& e) { return e.name == name; });
}

const ZipArchive::Entry& ZipArchive::find(const std::string& name) const {
  for (const Entry& e : entries_) {
    if (e.name == name) return e;
  }
  throw Error(path_, "ZIP entry " + name, "present in the archive", "missing");
}

constexpr std::uint64_t kMaxDeflateRatio = 64;

std::vector<std::uint8_t> ZipArchive::read(const std::string& name, std::size_t max_bytes) const {
  const Entry& e = find(name);
  const std::string field = "ZIP entry " + name;
  if (e.uncompressed > max_bytes) {
    throw Error(path_, field, "at most " + std::to_string(max_bytes) + " bytes uncompressed",
                std::to_string(e.uncompressed));
  }
  const std::uint64_t at = e.local_offset;
  if (at + 30 > bytes_.size() || load<std::uint32_t>(bytes_, at) != kLocalHeader) {
    throw Error(path_, field + " local header", "a local file header", "other bytes");
  }
  const std::uint64_t data = at + 30 + load<std::uint16_t>(bytes_, at + 26) +
                             load<std::uint16_t>(bytes_, at + 28);
  if (data + e.compressed > bytes_.size()) {
    throw Error(path_, field, std::to_string(e.compressed) + " bytes of data in the archive",
                "a truncated archive");
  }
  const auto* begin = reinterpret_cast<const std::uint8_t*>(bytes_.data()) + data;
  if (e.method == 0) {
    if (e.compressed != e.uncompressed) {
      throw Error(path_, field, "equal sizes for a stored entry",
                  std::to_string(e.compressed) + " and " + std::to_string(e.uncompressed));
    }
    return std::vector<std::uint8_t>(begin, begin + e.compressed);
  }
  if (e.method == 8) {
    // The archives sadsplat reads (.sog) hold WebP images, which deflate cannot shrink much, and
    // a small meta.json: an entry that claims to expand far beyond that is a bomb, refused before
    // it is inflated.
    if (e.uncompressed > kMaxDeflateRatio * e.compressed + (std::uint64_t{1} << 20)) {
      throw Error(path_, field,
                  "at most " + std::to_string(kMaxDeflateRatio) + "x its compressed " +
                      std::to_string(e.compressed) + " bytes (+1 MiB) uncompressed",
                  std::to_string(e.uncompressed) + " bytes");
    }
    return compression::inflateRaw(path_, field, begin, e.compressed, e.uncompressed);
  }
  throw Error(path_, field, "method 0 (stored) or 8 (deflate)",
              "not supported: method " + std::to_string(e.method));
}

namespace {

void put16(std::string& out, std::uint16_t v) { out.append(reinterpret_cast<const char*>(&v), 2); }
void put32(std::string& out, std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); }

}  // namespace

std::string storedZip(const std::string& path,
                      const std::vector<std::pair<std::string, std::string>>& entries) {
  std::string out, directory;
  for (const auto& [name, content] : entries) {
    if (out.size() + content.size() + name.size() + 30 >= 0xffffffffu) {
      throw Error(path, "ZIP archive", "under 4 GiB (no ZIP64)", "larger");
    }
    const auto crc = static_cast<std::uint32_t>(
        crc32(0L, reinterpret_cast<const Bytef*>(content.data()), static_cast<uInt>(content.size())));
    const auto offset = static_cast<std::uint32_t>(out.size());
    const auto size = static_cast<std::uint32_t>(content.size());
    // Local header: version 2.0, no flags, stored, no time, sizes, name.
    put32(out, kLocalHeader);
    put16(out, 20);
    put16(out, 0);
    put16(out, 0);
    put16(out, 0);
    put16(out, 0x21);  // 1980-01-01
    put32(out, crc);
    put32(out, size);
    put32(out, size);
    put16(out, static_cast<std::uint16_t>(name.size()));
    put16(out, 0);
    out += name;
    out += content;
    put32(directory, kDirectoryEntry);
    put16(directory, 20);
    put16(directory, 20);
    put16(directory, 0);
    put16(directory, 0);
    put16(directory, 0);
    put16(directory, 0x21);
    put32(directory, crc);
    put32(directory, size);
    put32(directory, size);
    put16(directory, static_cast<std::uint16_t>(name.size()));
    put16(directory, 0);
    put16(directory, 0);
    put16(directory, 0);
    put16(directory, 0);
    put32(directory, 0);
    put32(directory, offset);
    directory += name;
  }
  const auto directory_offset = static_cast<std::uint32_t>(out.size());
  out += directory;
  put32(out, kEndOfDirectory);
  put16(out, 0);
  put16(out, 0);
  put16(out, static_cast<std::uint16_t>(entries.size()));
  put16(out, static_cast<std::uint16_t>(entries.size()));
  put32(out, static_cast<std::uint32_t>(directory.size()));
  put32(out, directory_offset);
  put16(out, 0);
  return out;
}

}  // namespace io
}  // namespace sadsplat
