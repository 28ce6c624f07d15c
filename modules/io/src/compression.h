#pragma once
// The compressed streams of the splat formats: gzip (SPZ versions 1-3), zstd (SPZ version 4) and
// raw deflate (ZIP entries of SOG). Every decoder is bounded: it never produces more than the
// caller's limit, which comes from a count in the file's header, not from the compressed size.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace sadsplat {
namespace io {
namespace compression {

/// gzip-compresses `data` (zlib, default level).
std::vector<std::uint8_t> gzip(const std::string& path, const std::uint8_t* data, std::size_t size);

/// Inflates a gzip stream, stopping with sadsplat::Error as soon as the output would exceed the
/// limit or the stream is corrupt or truncated. `limit_of` is asked for the limit before every
/// 64 KiB of output, given what was inflated so far: once a header has come out, the limit can
/// follow from its count, so that a small file claiming few records cannot inflate to gigabytes.
std::vector<std::uint8_t> gunzip(
    const std::string& path, const std::uint8_t* data, std::size_t size,
    const std::function<std::size_t(const std::vector<std::uint8_t>&)>& limit_of);

/// Deflates `data` into a raw deflate stream (no zlib or gzip wrapper) at zlib `level` (1-9);
/// `huffman_only` skips the string matching (zlib's Z_HUFFMAN_ONLY: for prediction residuals
/// it compresses better and faster).
std::vector<std::uint8_t> deflateRaw(const std::string& path, const std::uint8_t* data,
                                     std::size_t size, int level, bool huffman_only = false);

/// Inflates a raw deflate stream (ZIP method 8) that must produce exactly `expected` bytes;
/// `expected` above `max_ratio` x `size` is refused before anything is allocated (deflate's own
/// limit is 1032:1; a Huffman-only stream's 8:1).
std::vector<std::uint8_t> inflateRaw(const std::string& path, const std::string& field,
                                     const std::uint8_t* data, std::size_t size,
                                     std::size_t expected, std::size_t max_ratio = 1032);

/// Whether this build can read and write zstd (SPZ version 4).
bool haveZstd();

/// zstd-compresses `data` (level 12, as SPZ's own writer).
std::vector<std::uint8_t> zstdCompress(const std::string& path, const std::uint8_t* data,
                                       std::size_t size);

/// Decompresses one zstd frame that must produce exactly `expected` bytes into `out`.
void zstdDecompress(const std::string& path, const std::string& field, const std::uint8_t* data,
                    std::size_t size, std::uint8_t* out, std::size_t expected);

}  // namespace compression
}  // namespace io
}  // namespace sadsplat
