#pragma once
/// \file scene_cache.h
/// \brief The scene cache: one versioned, checksummed binary file holding a whole imported
/// scene, readable without OpenCV. The format is documented in docs/formats.md.

#include <cstdint>
#include <string>

#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace io {

/// \brief Format version written by writeSceneCache and the only one readSceneCache accepts.
constexpr std::uint32_t kSceneCacheVersion = 1;

/// \brief Writes `scene` to `path` (atomically).
void writeSceneCache(const std::string& path, const Scene& scene);

/// \brief Reads a scene cache.
/// \throws sadsplat::Error on a missing file, wrong magic or version, truncated data, checksum
/// mismatch, non-finite camera values or label ids outside the class list
Scene readSceneCache(const std::string& path);

/// \brief Whether `path` starts with the scene cache magic (cheap: reads 8 bytes).
bool isSceneCache(const std::string& path);

/// \brief FNV-1a 64-bit hash, the cache's checksum.
std::uint64_t fnv1a64(const void* data, std::size_t size);

}  // namespace io
}  // namespace sadsplat
