#pragma once
/// \file scene_cache.h
/// \brief The scene cache: one versioned, checksummed binary file holding a whole imported
/// scene, readable without OpenCV. The format is documented in docs/formats.md.

#include <cstdint>
#include <string>

#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace io {

/// \brief Format version written by writeSceneCache: 3 stores images and region maps as
/// deflated prediction residuals (lossless). readSceneCache also accepts version 2 (the same
/// chunks with raw planes) and version 1 (version 2 whose checksum used a wrong FNV offset basis;
/// see docs/formats.md).
constexpr std::uint32_t kSceneCacheVersion = 3;

/// \brief Writes `scene` to `path` (atomically).
void writeSceneCache(const std::string& path, const Scene& scene);

/// \brief Reads a scene cache.
/// \throws sadsplat::Error on a missing file, wrong magic or version, truncated data, checksum
/// mismatch, non-finite camera values or label ids outside the class list
Scene readSceneCache(const std::string& path);

/// \brief Reads a scene cache's classes, cameras, roles, sparse points and georeference, and
/// where each view's pixels are, leaving the pixels in the file (every View's pixels_in_cache
/// set, its images and pseudo-labels empty): host memory of one chunk at a time. The whole file
/// is read once to check its checksum; the pixels are checked when readViewPixels reads them.
/// \throws sadsplat::Error as readSceneCache, except for errors inside images and pseudo-labels
Scene readSceneCacheWithoutPixels(const std::string& path);

/// \brief `view` with its pixels: itself when it holds them, else its images and pseudo-labels
/// read and decoded from its cache (safe to call from several threads at once).
/// \throws sadsplat::Error naming the cache and the view when the file cannot be read, changed
/// size, or the view's chunks are damaged (as readSceneCache checks them)
View readViewPixels(const View& view);

/// \brief The format version in a scene cache's header.
/// \throws sadsplat::Error when `path` is not a scene cache
std::uint32_t sceneCacheVersion(const std::string& path);

/// \brief Whether `path` is a regular file starting with the scene cache magic (reads 8 bytes).
bool isSceneCache(const std::string& path);

/// \brief FNV-1a 64-bit hash (offset basis 14695981039346656037, prime 1099511628211), the
/// checksum of version 2 caches.
std::uint64_t fnv1a64(const void* data, std::size_t size);

}  // namespace io
}  // namespace sadsplat
