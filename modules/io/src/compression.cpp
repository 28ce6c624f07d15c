#include "compression.h"

#include <zlib.h>

#include <algorithm>
#include <functional>
#include <limits>

#if SADSPLAT_HAVE_ZSTD
#include <zstd.h>
#endif

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace io {
namespace compression {
namespace {

// Runs inflate on a zlib stream set up by the caller, appending to `out` and refusing to produce
// more than `limit` bytes.
void inflateBounded(const std::string& path, const std::string& field, z_stream& s,
                    const std::function<std::size_t(const std::vector<std::uint8_t>&)>& limit_of,
                    std::vector<std::uint8_t>& out) {
  std::uint8_t buffer[65536];
  int rc = Z_OK;
  while (rc != Z_STREAM_END) {
    s.next_out = buffer;
    s.avail_out = sizeof(buffer);
    rc = inflate(&s, Z_NO_FLUSH);
    if (rc != Z_OK && rc != Z_STREAM_END) {
      inflateEnd(&s);
      throw Error(path, field, "a valid compressed stream", "corrupt or truncated data");
    }
    const std::size_t produced = sizeof(buffer) - s.avail_out;
    std::size_t limit = 0;
    try {
      limit = limit_of(out);  // may throw on a bad header: free zlib's state first
    } catch (...) {
      inflateEnd(&s);
      throw;
    }
    if (out.size() + produced > limit) {
      inflateEnd(&s);
      throw Error(path, field,
                  "at most " + std::to_string(limit) + " bytes uncompressed (what the header's "
                  "count needs)",
                  "more (a count that does not match the data, or a compression bomb)");
    }
    out.insert(out.end(), buffer, buffer + produced);
    if (produced == 0 && s.avail_in == 0 && rc != Z_STREAM_END) {
      inflateEnd(&s);
      throw Error(path, field, "a complete compressed stream", "truncated data");
    }
  }
  inflateEnd(&s);
}

}  // namespace

namespace {

// One deflate call over the whole input; `window_bits` picks the wrapper (16 + MAX_WBITS: gzip,
// -MAX_WBITS: raw), `what` names the stream in errors.
std::vector<std::uint8_t> deflateAll(const std::string& path, const char* what,
                                     const std::uint8_t* data, std::size_t size, int level,
                                     int window_bits, int strategy) {
  z_stream s{};
  if (deflateInit2(&s, level, Z_DEFLATED, window_bits, 9, strategy) != Z_OK) {
    throw Error(path, what, "zlib to initialise", "an initialisation failure");
  }
  std::vector<std::uint8_t> out(deflateBound(&s, size) + 64);
  s.next_in = const_cast<Bytef*>(data);
  s.avail_in = static_cast<uInt>(size);
  s.next_out = out.data();
  s.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&s, Z_FINISH);
  deflateEnd(&s);
  if (rc != Z_STREAM_END) throw Error(path, what, "the data compressed", "a zlib error");
  out.resize(out.size() - s.avail_out);
  return out;
}

}  // namespace

std::vector<std::uint8_t> gzip(const std::string& path, const std::uint8_t* data,
                               std::size_t size) {
  return deflateAll(path, "gzip", data, size, Z_DEFAULT_COMPRESSION, 16 + MAX_WBITS,
                    Z_DEFAULT_STRATEGY);
}

std::vector<std::uint8_t> deflateRaw(const std::string& path, const std::uint8_t* data,
                                     std::size_t size, int level, bool huffman_only) {
  // One call: zlib's counters are 32-bit, and a plane of the scene cache is far below 1 GiB.
  if (size > (std::size_t(1) << 30)) {
    throw Error(path, "deflate", "a block of at most 1 GiB", std::to_string(size) + " bytes");
  }
  return deflateAll(path, "deflate", data, size, level, -MAX_WBITS,
                    huffman_only ? Z_HUFFMAN_ONLY : Z_DEFAULT_STRATEGY);
}

std::vector<std::uint8_t> gunzip(
    const std::string& path, const std::uint8_t* data, std::size_t size,
    const std::function<std::size_t(const std::vector<std::uint8_t>&)>& limit_of) {
  z_stream s{};
  if (inflateInit2(&s, 16 + MAX_WBITS) != Z_OK) {
    throw Error(path, "gzip", "zlib to initialise", "an initialisation failure");
  }
  s.next_in = const_cast<Bytef*>(data);
  s.avail_in = static_cast<uInt>(size);
  std::vector<std::uint8_t> out;
  inflateBounded(path, "gzip data", s, limit_of, out);
  return out;
}

std::vector<std::uint8_t> inflateRaw(const std::string& path, const std::string& field,
                                     const std::uint8_t* data, std::size_t size,
                                     std::size_t expected, std::size_t max_ratio) {
  // Deflate expands at most 1032:1 (a 258-byte match per ~2 bits): a header asking for more than
  // that (or than the caller's format allows) of the bytes behind it is refused before anything
  // is allocated.
  if (expected / max_ratio > size + 1) {
    throw Error(path, field,
                "a compressed block of at least " + std::to_string(expected / max_ratio) +
                    " bytes for " + std::to_string(expected) + " bytes (a ratio of at most " +
                    std::to_string(max_ratio) + ":1)",
                std::to_string(size) + " bytes");
  }
  if (size > std::numeric_limits<uInt>::max()) {
    throw Error(path, field, "a compressed block below 4 GiB", std::to_string(size) + " bytes");
  }
  z_stream s{};
  if (inflateInit2(&s, -MAX_WBITS) != Z_OK) {
    throw Error(path, field, "zlib to initialise", "an initialisation failure");
  }
  s.next_in = const_cast<Bytef*>(data);
  s.avail_in = static_cast<uInt>(size);
  std::vector<std::uint8_t> out;
  out.reserve(expected);
  inflateBounded(
      path, field, s, [expected](const std::vector<std::uint8_t>&) { return expected; }, out);
  if (out.size() != expected) {
    throw Error(path, field, std::to_string(expected) + " bytes uncompressed",
                std::to_string(out.size()));
  }
  return out;
}

#if SADSPLAT_HAVE_ZSTD

bool haveZstd() { return true; }

std::vector<std::uint8_t> zstdCompress(const std::string& path, const std::uint8_t* data,
                                       std::size_t size) {
  std::vector<std::uint8_t> out(ZSTD_compressBound(size));
  const std::size_t n = ZSTD_compress(out.data(), out.size(), data, size, 12);
  if (ZSTD_isError(n)) throw Error(path, "zstd", "the data compressed", ZSTD_getErrorName(n));
  out.resize(n);
  return out;
}

void zstdDecompress(const std::string& path, const std::string& field, const std::uint8_t* data,
                    std::size_t size, std::uint8_t* out, std::size_t expected) {
  // ZSTD_decompress writes at most `expected` bytes: the header's count bounds the output.
  const std::size_t n = ZSTD_decompress(out, expected, data, size);
  if (ZSTD_isError(n)) {
    throw Error(path, field, "a valid zstd frame of " + std::to_string(expected) + " bytes",
                ZSTD_getErrorName(n));
  }
  if (n != expected) {
    throw Error(path, field, std::to_string(expected) + " bytes uncompressed", std::to_string(n));
  }
}

#else

bool haveZstd() { return false; }

std::vector<std::uint8_t> zstdCompress(const std::string& path, const std::uint8_t*,
                                       std::size_t) {
  throw Error(path, "SPZ version 4", "a build with libzstd (Debian: libzstd-dev)",
              "not supported: built without zstd");
}

void zstdDecompress(const std::string& path, const std::string&, const std::uint8_t*,
                    std::size_t, std::uint8_t*, std::size_t) {
  throw Error(path, "SPZ version 4", "a build with libzstd (Debian: libzstd-dev)",
              "not supported: built without zstd");
}

#endif

}  // namespace compression
}  // namespace io
}  // namespace sadsplat
