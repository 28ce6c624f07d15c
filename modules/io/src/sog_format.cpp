// PlayCanvas' SOG format, version 2, as splat-transform (its reference implementation) reads
// it: a ZIP holding meta.json and lossless WebP images whose pixels, in Gaussian order, carry
// the attributes. meta.json: count; means {mins, maxs, files [means_l, means_u]} (16-bit values
// of sign(x) log(1 + |x|) between mins and maxs); scales {codebook[256], files}; quats {files}
// (three components around 0.5 in units of 1/sqrt(2), alpha = 252 + index of the largest);
// sh0 {codebook[256], files} (r g b codebook indices, alpha = 255 sigmoid(opacity)); shN
// {count, bands, codebook[256], files [centroids, labels]} (optional). Axes as the PLY.
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <nlohmann/json.hpp>

#if SADSPLAT_HAVE_WEBP
#include <webp/decode.h>
#endif

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/gaussian_checks.h"
#include "sadsplat/io/splat_formats.h"
#include "splat_codec_support.h"
#include "zip_archive.h"

namespace sadsplat {
namespace io {
namespace {

constexpr std::size_t kMaxCount = std::size_t{1} << 28;
constexpr std::size_t kMaxEntryBytes = std::size_t{1} << 30;
constexpr std::size_t kMaxGaussiansPerByte = 64;
constexpr std::size_t kMaxMetaBytes = std::size_t{1} << 24;

struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgba;
};

const nlohmann::json& member(const std::string& path, const nlohmann::json& j,
                             const std::string& key, const std::string& where) {
  if (!j.is_object() || !j.contains(key)) {
    throw Error(path, "meta.json " + where + key, "present", "missing");
  }
  return j.at(key);
}

std::string fileName(const std::string& path, const nlohmann::json& group,
                     const std::string& where, std::size_t index) {
  const nlohmann::json& files = member(path, group, "files", where);
  if (!files.is_array() || files.size() <= index || !files[index].is_string()) {
    throw Error(path, "meta.json " + where + "files",
                "an array of at least " + std::to_string(index + 1) + " file names",
                files.dump().substr(0, 60));
  }
  return files[index].get<std::string>();
}

std::vector<float> numbers(const std::string& path, const nlohmann::json& group,
                           const std::string& key, const std::string& where, std::size_t count) {
  const nlohmann::json& j = member(path, group, key, where);
  if (!j.is_array() || j.size() != count) {
    throw Error(path, "meta.json " + where + key, "an array of " + std::to_string(count) +
                                                       " numbers",
                j.is_array() ? std::to_string(j.size()) + " entries" : j.dump().substr(0, 60));
  }
  std::vector<float> out;
  for (const auto& v : j) {
    // Finite as floats: 1e300 is a number but an infinite float scale or colour.
    if (!v.is_number() || !std::isfinite(v.get<double>()) ||
        std::fabs(v.get<double>()) > std::numeric_limits<float>::max()) {
      throw Error(path, "meta.json " + where + key, "finite numbers (as 32-bit floats)",
                  v.dump().substr(0, 30));
    }
    out.push_back(v.get<float>());
  }
  return out;
}

#if SADSPLAT_HAVE_WEBP

Image decodeWebp(const std::string& path, const ZipArchive& zip, const std::string& name,
                 std::size_t min_pixels) {
  const std::vector<std::uint8_t> bytes = zip.read(name, kMaxEntryBytes);
  Image image;
  if (!WebPGetInfo(bytes.data(), bytes.size(), &image.width, &image.height)) {
    throw Error(path, "ZIP entry " + name, "a WebP image", "other bytes");
  }
  const std::size_t pixels = static_cast<std::size_t>(image.width) * image.height;
  // An image is a texture of the Gaussians (padded to a convenient width) or a palette of at most
  // 65536 entries: anything far larger is refused before its pixels are allocated.
  const std::size_t max_pixels = 4 * min_pixels + (std::size_t{1} << 20);
  if (pixels > max_pixels) {
    throw Error(path, "ZIP entry " + name,
                "an image of at most " + std::to_string(max_pixels) + " pixels",
                std::to_string(image.width) + "x" + std::to_string(image.height));
  }
  if (pixels < min_pixels) {
    throw Error(path, "ZIP entry " + name,
                "at least " + std::to_string(min_pixels) + " pixels (one per Gaussian)",
                std::to_string(image.width) + "x" + std::to_string(image.height));
  }
  image.rgba.resize(pixels * 4);
  if (WebPDecodeRGBAInto(bytes.data(), bytes.size(), image.rgba.data(), image.rgba.size(),
                         image.width * 4) == nullptr) {
    throw Error(path, "ZIP entry " + name, "a decodable WebP image", "corrupt data");
  }
  return image;
}

#endif

}  // namespace

#if SADSPLAT_HAVE_WEBP

bool haveSogSupport() { return true; }

pcl::PointCloud<GaussianPoint> readSog(const std::string& path, SogFileInfo* info) {
  const std::string bytes = readWholeFile(path);
  const ZipArchive zip(path, bytes);
  const std::vector<std::uint8_t> meta_bytes = zip.read("meta.json", kMaxMetaBytes);
  const nlohmann::json meta =
      nlohmann::json::parse(meta_bytes.begin(), meta_bytes.end(), nullptr, false);
  if (meta.is_discarded() || !meta.is_object()) {
    throw Error(path, "meta.json", "a JSON object", "invalid JSON");
  }
  if (!meta.contains("version")) {
    throw Error(path, "meta.json version", "2", "not supported: version 1 (no version field)");
  }
  if (!meta["version"].is_number_integer() || meta["version"].get<long long>() != 2) {
    throw Error(path, "meta.json version", "2", meta["version"].dump().substr(0, 20));
  }
  const nlohmann::json& count_json = member(path, meta, "count", "");
  if (!count_json.is_number_unsigned() || count_json.get<std::uint64_t>() > kMaxCount) {
    throw Error(path, "meta.json count", "a Gaussian count up to 2^28",
                count_json.dump().substr(0, 20));
  }
  const std::size_t n = count_json.get<std::size_t>();
  // The images hold one pixel per Gaussian in lossless WebP; a file claiming more Gaussians than
  // kMaxGaussiansPerByte per byte of itself is refused before any image is decoded (real SOG files
  // take 10-20 bytes per Gaussian).
  if (n > kMaxGaussiansPerByte * bytes.size()) {
    throw Error(path, "meta.json count",
                "at most " + std::to_string(kMaxGaussiansPerByte) + " Gaussians per byte of the "
                "file (" + std::to_string(kMaxGaussiansPerByte * bytes.size()) + ")",
                std::to_string(n));
  }
  const nlohmann::json& means = member(path, meta, "means", "");
  const std::vector<float> mins = numbers(path, means, "mins", "means.", 3);
  const std::vector<float> maxs = numbers(path, means, "maxs", "means.", 3);
  const nlohmann::json& scales = member(path, meta, "scales", "");
  const std::vector<float> scale_book = numbers(path, scales, "codebook", "scales.", 256);
  const nlohmann::json& sh0 = member(path, meta, "sh0", "");
  const std::vector<float> colour_book = numbers(path, sh0, "codebook", "sh0.", 256);
  const nlohmann::json& quats = member(path, meta, "quats", "");

  const Image lo = decodeWebp(path, zip, fileName(path, means, "means.", 0), n);
  const Image hi = decodeWebp(path, zip, fileName(path, means, "means.", 1), n);
  const Image q = decodeWebp(path, zip, fileName(path, quats, "quats.", 0), n);
  const Image s = decodeWebp(path, zip, fileName(path, scales, "scales.", 0), n);
  const Image c = decodeWebp(path, zip, fileName(path, sh0, "sh0.", 0), n);

  pcl::PointCloud<GaussianPoint> cloud;
  cloud.resize(n);
  const auto inverseLog = [](float v) {
    const float e = std::exp(std::fabs(v)) - 1.0f;
    return v < 0 ? -e : e;
  };
  for (std::size_t i = 0; i < n; ++i) {
    GaussianPoint& p = cloud[i];
    const std::size_t o = 4 * i;
    float xyz[3];
    for (int k = 0; k < 3; ++k) {
      const float t = static_cast<float>(lo.rgba[o + k] | (hi.rgba[o + k] << 8)) / 65535.0f;
      const float span = maxs[k] - mins[k] != 0 ? maxs[k] - mins[k] : 1.0f;
      xyz[k] = inverseLog(mins[k] + span * t);
    }
    p.x = xyz[0];
    p.y = xyz[1];
    p.z = xyz[2];
    const int tag = q.rgba[o + 3];
    if (tag >= 252) {
      static const int kOthers[4][3] = {{1, 2, 3}, {0, 2, 3}, {0, 1, 3}, {0, 1, 2}};
      const int largest = tag - 252;
      float r[4] = {0, 0, 0, 0}, sum = 0;
      for (int k = 0; k < 3; ++k) {
        const float v = (q.rgba[o + k] / 255.0f * 2.0f - 1.0f) / std::sqrt(2.0f);
        r[kOthers[largest][k]] = v;
        sum += v * v;
      }
      r[largest] = std::sqrt(std::max(0.0f, 1.0f - sum));
      for (int k = 0; k < 4; ++k) p.rot[k] = r[k];  // rot_0..rot_3 = w x y z
    }  // else: an invalid tag, read as the identity (as splat-transform does)
    for (int k = 0; k < 3; ++k) {
      p.scale[k] = scale_book[s.rgba[o + k]];
      p.f_dc[k] = colour_book[c.rgba[o + k]];
    }
    p.opacity = splat_codec::logitOfAlpha(c.rgba[o + 3] / 255.0f);
  }

  int bands = 0;
  if (meta.contains("shN")) {
    const nlohmann::json& shn = meta["shN"];
    const nlohmann::json& bands_json = member(path, shn, "bands", "shN.");
    const nlohmann::json& palette_json = member(path, shn, "count", "shN.");
    if (!bands_json.is_number_integer() || bands_json.get<long long>() < 0 ||
        bands_json.get<long long>() > 3) {
      throw Error(path, "meta.json shN.bands", "0..3", bands_json.dump().substr(0, 20));
    }
    if (!palette_json.is_number_unsigned() || palette_json.get<std::uint64_t>() > 65536) {
      throw Error(path, "meta.json shN.count", "a palette size up to 65536",
                  palette_json.dump().substr(0, 20));
    }
    bands = bands_json.get<int>();
    const std::size_t palette = palette_json.get<std::size_t>();
    const int coeffs = bands == 1 ? 3 : bands == 2 ? 8 : bands == 3 ? 15 : 0;
    if (coeffs > 0) {
      const std::vector<float> book = numbers(path, shn, "codebook", "shN.", 256);
      const Image centroids = decodeWebp(path, zip, fileName(path, shn, "shN.", 0), 0);
      const Image labels = decodeWebp(path, zip, fileName(path, shn, "shN.", 1), n);
      if (centroids.width != 64 * coeffs) {
        throw Error(path, "ZIP entry " + fileName(path, shn, "shN.", 0),
                    "an image " + std::to_string(64 * coeffs) + " pixels wide (64 palette " +
                        "entries of " + std::to_string(coeffs) + " coefficients a row)",
                    std::to_string(centroids.width));
      }
      for (std::size_t i = 0; i < n; ++i) {
        const std::size_t label = labels.rgba[4 * i] | (labels.rgba[4 * i + 1] << 8);
        if (label >= palette) continue;  // as splat-transform: no SH for an invalid label
        const std::size_t row = label / 64;
        if (row >= static_cast<std::size_t>(centroids.height)) continue;
        for (int j = 0; j < coeffs; ++j) {
          const std::size_t x = (label % 64) * coeffs + j;
          const std::uint8_t* px = centroids.rgba.data() + 4 * (row * centroids.width + x);
          for (int ch = 0; ch < 3; ++ch) {
            cloud[i].f_rest[ch * kShRestPerChannel + j] = book[px[ch]];
          }
        }
      }
    }
  }
  splat_codec::finishCloud(cloud);
  const GaussianReadReport report = checkReadGaussians(path, cloud);
  if (info != nullptr) {
    info->version = 2;
    info->sh_bands = bands;
    info->num_points = n;
    info->clamped_opacities = report.clamped_opacities;
  }
  return cloud;
}

#else

bool haveSogSupport() { return false; }

pcl::PointCloud<GaussianPoint> readSog(const std::string& path, SogFileInfo*) {
  throw Error(path, "file type", "a build with libwebp (Debian: libwebp-dev) to read .sog",
              "not supported: built without libwebp");
}

#endif

}  // namespace io
}  // namespace sadsplat
