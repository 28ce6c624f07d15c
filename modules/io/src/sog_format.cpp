// PlayCanvas' SOG format, version 2, as splat-transform (its reference implementation) reads
// it: a ZIP holding meta.json and lossless WebP images whose pixels, in Gaussian order, carry
// the attributes. meta.json: count; means {mins, maxs, files [means_l, means_u]} (16-bit values
// of sign(x) log(1 + |x|) between mins and maxs); scales {codebook[256], files}; quats {files}
// (three components around 0.5 in units of 1/sqrt(2), alpha = 252 + index of the largest);
// sh0 {codebook[256], files} (r g b codebook indices, alpha = 255 sigmoid(opacity)); shN
// {count, bands, codebook[256], files [centroids, labels]} (optional). Axes as the PLY.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include <nlohmann/json.hpp>

#if SADSPLAT_HAVE_WEBP
#include <webp/decode.h>
#include <webp/encode.h>
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

namespace {

constexpr std::size_t kCodebook = 256;
constexpr std::size_t kMaxPalette = 65536;

// 256 values that stand for `values` with the least squared error (1D k-means: quantiles, then
// Lloyd's iterations on the sorted values), ascending.
std::vector<float> codebookOf(std::vector<float> values) {
  std::sort(values.begin(), values.end());
  std::vector<double> prefix(values.size() + 1, 0.0);
  for (std::size_t i = 0; i < values.size(); ++i) prefix[i + 1] = prefix[i] + values[i];
  std::vector<float> book(kCodebook);
  for (std::size_t k = 0; k < kCodebook; ++k) {
    book[k] = values[std::min(values.size() - 1, (2 * k + 1) * values.size() / (2 * kCodebook))];
  }
  for (int iteration = 0; iteration < 16; ++iteration) {
    std::size_t from = 0;
    for (std::size_t k = 0; k < kCodebook; ++k) {
      const std::size_t to =
          k + 1 == kCodebook
              ? values.size()
              : static_cast<std::size_t>(std::upper_bound(values.begin(), values.end(),
                                                          0.5f * (book[k] + book[k + 1])) -
                                         values.begin());
      if (to > from) book[k] = static_cast<float>((prefix[to] - prefix[from]) / (to - from));
      from = std::max(from, to);
    }
    std::sort(book.begin(), book.end());
  }
  return book;
}

// The index of the codebook entry nearest to v (the book ascending).
std::uint8_t nearestEntry(const std::vector<float>& book, float v) {
  const auto it = std::lower_bound(book.begin(), book.end(), v);
  std::size_t k = static_cast<std::size_t>(it - book.begin());
  if (k == book.size() || (k > 0 && v - book[k - 1] < book[k] - v)) --k;
  return static_cast<std::uint8_t>(k);
}

// A lossless WebP of an RGBA image.
std::string encodeWebp(const std::string& path, const std::vector<std::uint8_t>& rgba, int width,
                       int height, const std::string& name) {
  std::uint8_t* out = nullptr;
  const std::size_t size = WebPEncodeLosslessRGBA(rgba.data(), width, height, width * 4, &out);
  if (size == 0 || out == nullptr) {
    throw Error(path, "ZIP entry " + name, "a WebP image libwebp can encode",
                std::to_string(width) + "x" + std::to_string(height) + " failed");
  }
  std::string bytes(reinterpret_cast<const char*>(out), size);
  WebPFree(out);
  return bytes;
}

}  // namespace

void writeSog(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud,
              const SogWriteOptions& options) {
  if (options.sh_degree < 0 || options.sh_degree > kMaxShDegree) {
    throw Error(path, "SH degree option", "0..3", std::to_string(options.sh_degree));
  }
  checkWritableGaussians(path, cloud);
  const std::size_t n = cloud.size();
  if (n == 0) throw Error(path, "Gaussians", "at least one", "an empty cloud");
  if (n > kMaxCount) throw Error(path, "Gaussian count", "at most 2^28", std::to_string(n));
  // One pixel per Gaussian, row-major, in images 4-pixel aligned.
  const int width = static_cast<int>((static_cast<std::size_t>(std::ceil(std::sqrt(double(n)))) + 3) / 4 * 4);
  const int height = static_cast<int>((n + width - 1) / width);
  const std::size_t pixels = static_cast<std::size_t>(width) * height;
  auto image = [&] { return std::vector<std::uint8_t>(4 * pixels, 0); };

  // Means: sign(x) log(1 + |x|) per axis, 16 bits between its min and max (low and high bytes).
  std::array<float, 3> lo{}, hi{};
  lo.fill(std::numeric_limits<float>::max());
  hi.fill(std::numeric_limits<float>::lowest());
  const auto logOf = [](float v) { return v < 0 ? -std::log1p(-v) : std::log1p(v); };
  for (const GaussianPoint& p : cloud) {
    const float xyz[3] = {p.x, p.y, p.z};
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], logOf(xyz[k]));
      hi[k] = std::max(hi[k], logOf(xyz[k]));
    }
  }
  std::vector<std::uint8_t> means_l = image(), means_u = image(), quats = image(),
                            scales = image(), sh0 = image();
  std::vector<float> scale_values, colour_values;
  scale_values.reserve(3 * n);
  colour_values.reserve(3 * n);
  for (const GaussianPoint& p : cloud) {
    for (int k = 0; k < 3; ++k) {
      scale_values.push_back(p.scale[k]);
      colour_values.push_back(p.f_dc[k]);
    }
  }
  const std::vector<float> scale_book = codebookOf(scale_values);
  const std::vector<float> colour_book = codebookOf(colour_values);
  for (std::size_t i = 0; i < n; ++i) {
    const GaussianPoint& p = cloud[i];
    const std::size_t o = 4 * i;
    const float xyz[3] = {p.x, p.y, p.z};
    for (int k = 0; k < 3; ++k) {
      const float span = hi[k] - lo[k] > 0 ? hi[k] - lo[k] : 1.0f;
      const auto q = static_cast<std::uint32_t>(
          std::lround(std::clamp((logOf(xyz[k]) - lo[k]) / span, 0.0f, 1.0f) * 65535.0f));
      means_l[o + k] = static_cast<std::uint8_t>(q & 0xff);
      means_u[o + k] = static_cast<std::uint8_t>(q >> 8);
      scales[o + k] = nearestEntry(scale_book, p.scale[k]);
      sh0[o + k] = nearestEntry(colour_book, p.f_dc[k]);
    }
    means_l[o + 3] = means_u[o + 3] = scales[o + 3] = 255;
    sh0[o + 3] = splat_codec::toByte(255.0f * splat_codec::sigmoid(p.opacity));
    // Quaternion (w, x, y, z): the largest component made positive and left out, the other three
    // in units of 1/sqrt(2) around 0.5, the alpha 252 + the largest's index.
    auto q = splat_codec::unitQuaternion(p);
    int largest = 0;
    for (int k = 1; k < 4; ++k) {
      if (std::fabs(q[k]) > std::fabs(q[largest])) largest = k;
    }
    if (q[largest] < 0) {
      for (float& v : q) v = -v;
    }
    int j = 0;
    for (int k = 0; k < 4; ++k) {
      if (k == largest) continue;
      quats[o + j++] = splat_codec::toByte((q[k] * std::sqrt(2.0f) * 0.5f + 0.5f) * 255.0f);
    }
    quats[o + 3] = static_cast<std::uint8_t>(252 + largest);
  }
  nlohmann::json meta = {
      {"version", 2},
      {"count", n},
      {"means", {{"mins", lo}, {"maxs", hi}, {"files", {"means_l.webp", "means_u.webp"}}}},
      {"scales", {{"codebook", scale_book}, {"files", {"scales.webp"}}}},
      {"quats", {{"files", {"quats.webp"}}}},
      {"sh0", {{"codebook", colour_book}, {"files", {"sh0.webp"}}}}};
  std::vector<std::pair<std::string, std::string>> entries = {
      {"means_l.webp", encodeWebp(path, means_l, width, height, "means_l.webp")},
      {"means_u.webp", encodeWebp(path, means_u, width, height, "means_u.webp")},
      {"quats.webp", encodeWebp(path, quats, width, height, "quats.webp")},
      {"scales.webp", encodeWebp(path, scales, width, height, "scales.webp")},
      {"sh0.webp", encodeWebp(path, sh0, width, height, "sh0.webp")}};
  // Higher SH degrees: a palette of one entry per Gaussian (exact up to the 8-bit codebook)
  // while there are at most 65536 Gaussians; beyond, none (said by the returned note).
  const int coeffs = options.sh_degree == 1 ? 3 : options.sh_degree == 2 ? 8 : options.sh_degree == 3 ? 15 : 0;
  if (coeffs > 0 && n <= kMaxPalette) {
    std::vector<float> values;
    values.reserve(3 * coeffs * n);
    for (const GaussianPoint& p : cloud) {
      for (int ch = 0; ch < 3; ++ch) {
        for (int k = 0; k < coeffs; ++k) values.push_back(p.f_rest[ch * kShRestPerChannel + k]);
      }
    }
    const std::vector<float> book = codebookOf(values);
    const int centroid_width = 64 * coeffs;
    const int centroid_height = static_cast<int>((n + 63) / 64);
    std::vector<std::uint8_t> centroids(4 * static_cast<std::size_t>(centroid_width) * centroid_height, 0);
    std::vector<std::uint8_t> labels = image();
    for (std::size_t i = 0; i < n; ++i) {
      const std::size_t row = i / 64;
      for (int k = 0; k < coeffs; ++k) {
        const std::size_t x = (i % 64) * coeffs + k;
        std::uint8_t* px = centroids.data() + 4 * (row * centroid_width + x);
        for (int ch = 0; ch < 3; ++ch) {
          px[ch] = nearestEntry(book, cloud[i].f_rest[ch * kShRestPerChannel + k]);
        }
        px[3] = 255;
      }
      labels[4 * i] = static_cast<std::uint8_t>(i & 0xff);
      labels[4 * i + 1] = static_cast<std::uint8_t>(i >> 8);
      labels[4 * i + 3] = 255;
    }
    meta["shN"] = {{"count", n},
                   {"bands", options.sh_degree},
                   {"codebook", book},
                   {"files", {"shN_centroids.webp", "shN_labels.webp"}}};
    entries.emplace_back("shN_centroids.webp", encodeWebp(path, centroids, centroid_width,
                                                          centroid_height, "shN_centroids.webp"));
    entries.emplace_back("shN_labels.webp",
                         encodeWebp(path, labels, width, height, "shN_labels.webp"));
  }
  entries.insert(entries.begin(), {"meta.json", meta.dump()});
  const std::string zip = storedZip(path, entries);
  writeFileAtomically(path, [&](std::ostream& out) {
    out.write(zip.data(), static_cast<std::streamsize>(zip.size()));
  });
}

#else

bool haveSogSupport() { return false; }

pcl::PointCloud<GaussianPoint> readSog(const std::string& path, SogFileInfo*) {
  throw Error(path, "file type", "a build with libwebp (Debian: libwebp-dev) to read .sog",
              "not supported: built without libwebp");
}

void writeSog(const std::string& path, const pcl::PointCloud<GaussianPoint>&,
              const SogWriteOptions&) {
  throw Error(path, "file type", "a build with libwebp (Debian: libwebp-dev) to write .sog",
              "not supported: built without libwebp");
}

#endif

}  // namespace io
}  // namespace sadsplat
