// PlayCanvas' compressed PLY (SuperSplat, splat-transform): a `chunk` element with float ranges
// per 256 Gaussians, a `vertex` element of four packed uint32 (position 11-10-11 bits, rotation
// as two index bits and three 10-bit components, log-scale 11-10-11 bits, colour and opacity
// 8-8-8-8 bits), and an optional `sh` element of uint8 coefficients. Read as splat-transform's
// decompressPly reads it.
#include <cmath>
#include <cstring>
#include <map>

#include "ply_codec.h"
#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/gaussian_checks.h"
#include "sadsplat/io/splat_formats.h"
#include "splat_codec_support.h"

namespace sadsplat {
namespace io {
namespace {

using namespace ply;  // NOLINT: the container format this file reads

constexpr std::size_t kChunkSize = 256;
constexpr std::size_t kMaxHeaderBytes = std::size_t{1} << 16;

const char* const kChunkRanges[] = {"min_x",       "min_y",       "min_z",       "max_x",
                                    "max_y",       "max_z",       "min_scale_x", "min_scale_y",
                                    "min_scale_z", "max_scale_x", "max_scale_y", "max_scale_z"};
const char* const kChunkColours[] = {"min_r", "min_g", "min_b", "max_r", "max_g", "max_b"};
const char* const kPacked[] = {"packed_position", "packed_rotation", "packed_scale",
                               "packed_color"};

const PlyElement* findElement(const PlyHeader& header, const std::string& name) {
  for (const PlyElement& e : header.elements) {
    if (e.name == name) return &e;
  }
  return nullptr;
}

bool hasScalar(const PlyElement& e, const std::string& name, PlyType type) {
  for (const PlyProperty& p : e.properties) {
    if (p.name == name) return !p.is_list && p.type == type;
  }
  return false;
}

bool looksCompressed(const PlyHeader& header) {
  const PlyElement* chunk = findElement(header, "chunk");
  const PlyElement* vertex = findElement(header, "vertex");
  if (chunk == nullptr || vertex == nullptr) return false;
  for (const char* n : kPacked) {
    if (!hasScalar(*vertex, n, PlyType::kUInt32)) return false;
  }
  return hasScalar(*chunk, "min_x", PlyType::kFloat32);
}

float unorm(std::uint32_t value, int bits) {
  const std::uint32_t top = (1u << bits) - 1;
  return static_cast<float>(value & top) / static_cast<float>(top);
}

float lerp(float a, float b, float t) { return a * (1 - t) + b * t; }

}  // namespace

bool isCompressedPly(const std::string& path) {
  const std::string start = readFileStart(path, kMaxHeaderBytes);
  if (start.compare(0, 3, "ply") != 0 || start.find("end_header") == std::string::npos) {
    return false;
  }
  return looksCompressed(parseHeader(path, start));
}

pcl::PointCloud<GaussianPoint> readCompressedPly(const std::string& path,
                                                 CompressedPlyInfo* info) {
  const std::string bytes = readWholeFile(path);
  const PlyHeader header = parseHeader(path, bytes);
  if (!looksCompressed(header)) {
    throw Error(path, "header",
                "a compressed PLY: element chunk (float min_x ...) and element vertex (uint "
                "packed_position packed_rotation packed_scale packed_color)",
                "another layout");
  }
  if (header.format != PlyFormat::kBinaryLittleEndian) {
    throw Error(path, "format", "binary_little_endian (as PlayCanvas writes it)",
                header.format_name);
  }
  const PlyElement& chunk = *findElement(header, "chunk");
  const PlyElement& vertex = *findElement(header, "vertex");
  const PlyElement* sh = findElement(header, "sh");
  for (const char* n : kChunkRanges) {
    if (!hasScalar(chunk, n, PlyType::kFloat32)) {
      throw Error(path, std::string("chunk property ") + n, "a float property", "missing");
    }
  }
  const bool chunk_colours = chunk.properties.size() == 18;
  if (chunk.properties.size() != 12 && !chunk_colours) {
    throw Error(path, "element chunk", "12 or 18 float properties",
                std::to_string(chunk.properties.size()));
  }
  if (chunk_colours) {
    for (const char* n : kChunkColours) {
      if (!hasScalar(chunk, n, PlyType::kFloat32)) {
        throw Error(path, std::string("chunk property ") + n, "a float property", "missing");
      }
    }
  }
  if (chunk.count != (vertex.count + kChunkSize - 1) / kChunkSize) {
    throw Error(path, "element chunk count",
                std::to_string((vertex.count + kChunkSize - 1) / kChunkSize) + " for " +
                    std::to_string(vertex.count) + " vertices (256 per chunk)",
                std::to_string(chunk.count));
  }
  int degree = 0;
  if (sh != nullptr) {
    const std::size_t k = sh->properties.size();
    degree = k == 9 ? 1 : k == 24 ? 2 : k == 45 ? 3 : -1;
    if (degree < 0) {
      throw Error(path, "element sh", "9, 24 or 45 uchar properties", std::to_string(k));
    }
    for (const PlyProperty& p : sh->properties) {
      if (p.is_list || p.type != PlyType::kUInt8) {
        throw Error(path, "sh property " + p.name, "a uchar property", "another type");
      }
    }
    if (sh->count != vertex.count) {
      throw Error(path, "element sh count", std::to_string(vertex.count) + " (one per vertex)",
                  std::to_string(sh->count));
    }
  }
  for (const PlyElement& e : header.elements) {
    if (&e != &chunk && &e != &vertex && &e != sh) {
      throw Error(path, "element " + e.name, "only chunk, vertex and sh", e.name);
    }
  }

  // Every element is read in file order; each one's size is checked before it is read.
  ValueDecoder decoder(path, bytes, header.data_offset, header.format);
  std::map<std::string, std::vector<double>> chunk_values;
  std::vector<std::uint32_t> packed[4];
  std::vector<std::uint8_t> sh_bytes;
  for (const PlyElement& e : header.elements) {
    checkElementFits(path, decoder, e, header.format);
    for (std::size_t i = 0; i < e.count; ++i) {
      const std::string what = "element " + e.name + " item " + std::to_string(i);
      for (std::size_t k = 0; k < e.properties.size(); ++k) {
        const PlyProperty& p = e.properties[k];
        const double v = decoder.next(p.type, what);
        if (&e == &chunk) {
          chunk_values[p.name].push_back(v);
        } else if (&e == &vertex) {
          for (int j = 0; j < 4; ++j) {
            if (p.name == kPacked[j]) packed[j].push_back(static_cast<std::uint32_t>(v));
          }
        } else {
          sh_bytes.push_back(static_cast<std::uint8_t>(v));
        }
      }
    }
  }
  if (decoder.bytesLeft() != 0) {
    throw Error(path, "data", "nothing after the last element",
                std::to_string(decoder.bytesLeft()) + " bytes");
  }

  // The chunk ranges in kChunkRanges / kChunkColours order, looked up once.
  std::vector<const std::vector<double>*> ranges;
  for (const char* n : kChunkRanges) ranges.push_back(&chunk_values[n]);
  if (chunk_colours) {
    for (const char* n : kChunkColours) ranges.push_back(&chunk_values[n]);
  }
  const auto range = [&](int k, std::size_t c) { return static_cast<float>((*ranges[k])[c]); };
  pcl::PointCloud<GaussianPoint> cloud;
  cloud.resize(vertex.count);
  const std::size_t rest = sh != nullptr ? sh->properties.size() / 3 : 0;
  for (std::size_t i = 0; i < vertex.count; ++i) {
    GaussianPoint& p = cloud[i];
    const std::size_t c = i / kChunkSize;
    const std::uint32_t pos = packed[0][i], rot = packed[1][i], scl = packed[2][i],
                        col = packed[3][i];
    p.x = lerp(range(0, c), range(3, c), unorm(pos >> 21, 11));
    p.y = lerp(range(1, c), range(4, c), unorm(pos >> 11, 10));
    p.z = lerp(range(2, c), range(5, c), unorm(pos, 11));
    p.scale[0] = lerp(range(6, c), range(9, c), unorm(scl >> 21, 11));
    p.scale[1] = lerp(range(7, c), range(10, c), unorm(scl >> 11, 10));
    p.scale[2] = lerp(range(8, c), range(11, c), unorm(scl, 11));
    // Rotation: the largest component's index in the top two bits (rot_0..rot_3 order), the
    // other three in units of 1/sqrt(2) around 0.5.
    const float norm = std::sqrt(2.0f);
    const float a = (unorm(rot >> 20, 10) - 0.5f) * norm;
    const float b = (unorm(rot >> 10, 10) - 0.5f) * norm;
    const float d = (unorm(rot, 10) - 0.5f) * norm;
    const float m = std::sqrt(std::max(0.0f, 1.0f - (a * a + b * b + d * d)));
    const unsigned which = rot >> 30;
    const float q[4][4] = {{m, a, b, d}, {a, m, b, d}, {a, b, m, d}, {a, b, d, m}};
    for (int k = 0; k < 4; ++k) p.rot[k] = q[which][k];
    float rgb[3] = {unorm(col >> 24, 8), unorm(col >> 16, 8), unorm(col >> 8, 8)};
    if (chunk_colours) {
      rgb[0] = lerp(range(12, c), range(15, c), rgb[0]);
      rgb[1] = lerp(range(13, c), range(16, c), rgb[1]);
      rgb[2] = lerp(range(14, c), range(17, c), rgb[2]);
    }
    for (int k = 0; k < 3; ++k) p.f_dc[k] = (rgb[k] - 0.5f) / splat_codec::kC0;
    p.opacity = splat_codec::logitOfAlpha(unorm(col, 8));
    for (std::size_t k = 0; k < 3 * rest; ++k) {
      const std::uint8_t v = sh_bytes[i * 3 * rest + k];
      const float n = v == 0 ? 0.0f : v == 255 ? 1.0f : (v + 0.5f) / 256.0f;
      // f_rest_k is channel-major with `rest` coefficients per channel, as the 3DGS PLY.
      p.f_rest[(k / rest) * kShRestPerChannel + k % rest] = (n - 0.5f) * 8.0f;
    }
  }
  splat_codec::finishCloud(cloud);
  const GaussianReadReport report = checkReadGaussians(path, cloud);
  if (info != nullptr) {
    info->chunks = chunk.count;
    info->sh_degree = degree;
    info->clamped_opacities = report.clamped_opacities;
  }
  return cloud;
}

}  // namespace io
}  // namespace sadsplat
