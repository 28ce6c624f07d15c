// Gaussians as glTF binary with KHR_gaussian_splatting (see gltf_splats.h).
#include "sadsplat/io/gltf_splats.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <set>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/gaussian_checks.h"
#include "sadsplat/io/splat_formats.h"
#include "splat_codec_support.h"

namespace sadsplat {
namespace io {
namespace {

using namespace splat_codec;  // NOLINT: the codec helpers of this family of formats
using json = nlohmann::json;

constexpr std::uint32_t kGlbMagic = 0x46546c67;  // "glTF"
constexpr std::uint32_t kJsonChunk = 0x4e4f534a;  // "JSON"
constexpr std::uint32_t kBinChunk = 0x004e4942;   // "BIN\0"
constexpr int kFloat = 5126;
constexpr int kUnsignedByte = 5121;
constexpr int kArrayBuffer = 34962;
constexpr std::uint32_t kNullFeature = 65535;
constexpr const char* kSplat = "KHR_gaussian_splatting";
constexpr const char* kSpz = "KHR_gaussian_splatting_compression_spz_2";
constexpr const char* kPrefix = "KHR_gaussian_splatting:";
constexpr std::size_t kMaxGlbBytes = std::size_t{1} << 31;

// The binary chunk and the JSON views into it.
class BinaryBuilder {
 public:
  // Appends `bytes` as a new buffer view (8-byte aligned); returns its index.
  int addView(const void* bytes, std::size_t size, bool vertex_data) {
    while (bin_.size() % 8 != 0) bin_.push_back(0);
    json view = {{"buffer", 0}, {"byteOffset", bin_.size()}, {"byteLength", size}};
    if (vertex_data) view["target"] = kArrayBuffer;
    const auto* b = static_cast<const std::uint8_t*>(bytes);
    bin_.insert(bin_.end(), b, b + size);
    views_.push_back(view);
    return static_cast<int>(views_.size()) - 1;
  }
  // Adds an accessor (over a new view of `bytes`, or none when `bytes` is null).
  int addAccessor(const void* bytes, std::size_t size, std::size_t count, const char* type,
                  int component, bool normalized = false) {
    json a = {{"componentType", component}, {"count", count}, {"type", type}};
    if (normalized) a["normalized"] = true;
    if (bytes != nullptr) a["bufferView"] = addView(bytes, size, true);
    accessors_.push_back(a);
    return static_cast<int>(accessors_.size()) - 1;
  }
  json& accessor(int i) { return accessors_[static_cast<std::size_t>(i)]; }
  const json& views() const { return views_; }
  const json& accessors() const { return accessors_; }
  std::vector<std::uint8_t>& bin() { return bin_; }

 private:
  std::vector<std::uint8_t> bin_;
  json views_ = json::array();
  json accessors_ = json::array();
};

std::string shName(int degree, int coefficient) {
  return std::string(kPrefix) + "SH_DEGREE_" + std::to_string(degree) + "_COEF_" +
         std::to_string(coefficient);
}

// First SH rest index (per channel) of a degree's coefficients: 0, 3, 8.
int shRestStart(int degree) { return degree * degree - 1; }

void addFeatureIds(const pcl::PointCloud<GaussianPoint>& cloud, const GltfSplatOptions& options,
                   BinaryBuilder& b, json& primitive, json& gltf, json& used) {
  if (options.classes.empty()) return;
  // Float IDs (exact below 2^24): a vertex attribute's elements must be 4-byte aligned, which
  // tightly packed 16-bit IDs are not.
  std::vector<float> ids(cloud.size());
  std::set<std::uint32_t> present;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const std::uint32_t label = cloud[i].label;
    const std::uint32_t id = label < options.classes.size() ? label : kNullFeature;
    ids[i] = static_cast<float>(id);
    if (id != kNullFeature) present.insert(id);
  }
  if (present.empty()) return;
  primitive["attributes"]["_FEATURE_ID_0"] =
      b.addAccessor(ids.data(), ids.size() * 4, ids.size(), "SCALAR", kFloat);
  primitive["extensions"]["EXT_mesh_features"] = {
      {"featureIds",
       json::array({{{"featureCount", present.size()},
                     {"attribute", 0},
                     {"nullFeatureId", kNullFeature},
                     {"propertyTable", 0},
                     {"label", "semantic_class"}}})}};
  std::string names;
  std::vector<std::uint32_t> offsets = {0};
  std::vector<std::uint8_t> colors;
  for (const ClassInfo& c : options.classes) {
    names += c.name;
    offsets.push_back(static_cast<std::uint32_t>(names.size()));
    colors.insert(colors.end(), c.color.begin(), c.color.end());
  }
  const int names_view = b.addView(names.data(), names.size(), false);
  const int offsets_view = b.addView(offsets.data(), offsets.size() * 4, false);
  const int colors_view = b.addView(colors.data(), colors.size(), false);
  gltf["extensions"]["EXT_structural_metadata"] = {
      {"schema",
       {{"id", "sadsplat_semantic_classes"},
        {"classes",
         {{"semantic_class",
           {{"name", "Semantic class"},
            {"properties",
             {{"name", {{"type", "STRING"}, {"required", true}}},
              {"color", {{"type", "VEC3"}, {"componentType", "UINT8"}, {"required", true}}}}}}}}}}},
      {"propertyTables",
       json::array({{{"class", "semantic_class"},
                     {"count", options.classes.size()},
                     {"properties",
                      {{"name",
                        {{"values", names_view},
                         {"stringOffsets", offsets_view},
                         {"stringOffsetType", "UINT32"}}},
                       {"color", {{"values", colors_view}}}}}}})}};
  used.push_back("EXT_mesh_features");
  used.push_back("EXT_structural_metadata");
}

}  // namespace

std::vector<std::uint8_t> encodeSplatGlb(const std::string& name,
                                         const pcl::PointCloud<GaussianPoint>& cloud,
                                         const GltfSplatOptions& options) {
  if (options.sh_degree < 0 || options.sh_degree > kMaxShDegree) {
    throw Error(name, "SH degree option", "0..3", std::to_string(options.sh_degree));
  }
  if (options.classes.size() >= kNullFeature) {
    throw Error(name, "classes", "fewer than 65535 (16-bit feature IDs)",
                std::to_string(options.classes.size()));
  }
  checkWritableGaussians(name, cloud);
  if (cloud.empty()) throw Error(name, "Gaussians", "at least one", "an empty cloud");
  const std::size_t n = cloud.size();
  BinaryBuilder b;
  json primitive = {{"mode", 0}, {"attributes", json::object()}};
  json& attributes = primitive["attributes"];
  json used = json::array({kSplat});
  json required = json::array();
  json splat = {{"kernel", "ellipse"},
                {"colorSpace", "srgb_rec709_display"},
                {"sortingMethod", "cameraDistance"},
                {"projection", "perspective"}};

  std::vector<float> position(3 * n), rotation(4 * n), scale(3 * n), opacity(n), dc(3 * n);
  std::vector<std::uint8_t> color(4 * n);
  std::array<float, 3> lo{}, hi{};
  lo.fill(std::numeric_limits<float>::max());
  hi.fill(std::numeric_limits<float>::lowest());
  for (std::size_t i = 0; i < n; ++i) {
    const GaussianPoint& p = cloud[i];
    const float xyz[3] = {p.x, p.y, p.z};
    for (int k = 0; k < 3; ++k) {
      position[3 * i + k] = xyz[k];
      lo[k] = std::min(lo[k], xyz[k]);
      hi[k] = std::max(hi[k], xyz[k]);
      scale[3 * i + k] = std::exp(p.scale[k]);
      dc[3 * i + k] = p.f_dc[k];
      color[4 * i + k] = toByte(255.0f * (0.5f + kC0 * p.f_dc[k]));
    }
    const float alpha = sigmoid(p.opacity);
    opacity[i] = alpha;
    color[4 * i + 3] = toByte(255.0f * alpha);
    const auto q = unitQuaternion(p);  // (w, x, y, z) -> (x, y, z, w)
    rotation[4 * i] = q[1];
    rotation[4 * i + 1] = q[2];
    rotation[4 * i + 2] = q[3];
    rotation[4 * i + 3] = q[0];
  }
  const bool plain = !options.spz;
  auto data = [&](const void* bytes) { return plain ? bytes : nullptr; };
  attributes["POSITION"] =
      b.addAccessor(data(position.data()), position.size() * 4, n, "VEC3", kFloat);
  b.accessor(attributes["POSITION"].get<int>())["min"] = lo;
  b.accessor(attributes["POSITION"].get<int>())["max"] = hi;
  attributes["COLOR_0"] =
      b.addAccessor(data(color.data()), color.size(), n, "VEC4", kUnsignedByte, true);
  attributes[std::string(kPrefix) + "SCALE"] =
      b.addAccessor(data(scale.data()), scale.size() * 4, n, "VEC3", kFloat);
  attributes[std::string(kPrefix) + "ROTATION"] =
      b.addAccessor(data(rotation.data()), rotation.size() * 4, n, "VEC4", kFloat);
  if (plain) {
    attributes[std::string(kPrefix) + "OPACITY"] =
        b.addAccessor(opacity.data(), opacity.size() * 4, n, "SCALAR", kFloat);
    attributes[shName(0, 0)] = b.addAccessor(dc.data(), dc.size() * 4, n, "VEC3", kFloat);
  }
  for (int l = 1; l <= options.sh_degree; ++l) {
    for (int c = 0; c < 2 * l + 1; ++c) {
      std::vector<float> coefficient(3 * n);
      const int k = shRestStart(l) + c;
      for (std::size_t i = 0; i < n; ++i) {
        for (int ch = 0; ch < 3; ++ch) {
          coefficient[3 * i + ch] = cloud[i].f_rest[ch * kShRestPerChannel + k];
        }
      }
      attributes[shName(l, c)] =
          b.addAccessor(data(coefficient.data()), coefficient.size() * 4, n, "VEC3", kFloat);
    }
  }
  if (options.spz) {
    SpzWriteOptions spz;
    spz.version = 3;
    spz.sh_degree = options.sh_degree;
    spz.axes_as_stored = true;
    const std::vector<std::uint8_t> payload = encodeSpz(name, cloud, spz);
    splat["extensions"][kSpz] = {{"bufferView", b.addView(payload.data(), payload.size(), false)}};
    used.push_back(kSpz);
    required = json::array({kSplat, kSpz});
  }
  primitive["extensions"][kSplat] = splat;
  json gltf = {{"asset", {{"version", "2.0"}, {"generator", options.generator}}},
               {"scene", 0},
               {"scenes", json::array({{{"nodes", json::array({0})}}})},
               {"nodes", json::array({{{"mesh", 0}}})}};
  addFeatureIds(cloud, options, b, primitive, gltf, used);
  gltf["meshes"] = json::array({{{"primitives", json::array({primitive})}}});
  gltf["extensionsUsed"] = used;
  if (!required.empty()) gltf["extensionsRequired"] = required;
  std::vector<std::uint8_t>& bin = b.bin();
  while (bin.size() % 4 != 0) bin.push_back(0);
  gltf["buffers"] = json::array({{{"byteLength", bin.size()}}});
  gltf["bufferViews"] = b.views();
  gltf["accessors"] = b.accessors();
  std::string text = gltf.dump();
  while (text.size() % 4 != 0) text.push_back(' ');
  const std::size_t total = 12 + 8 + text.size() + 8 + bin.size();
  if (total >= kMaxGlbBytes) {
    throw Error(name, "size", "a GLB under 2 GiB (split the model into tiles: `sadsplat tiles`)",
                std::to_string(total) + " bytes");
  }
  std::vector<std::uint8_t> glb(total);
  auto put = [&](std::size_t at, std::uint32_t v) { std::memcpy(glb.data() + at, &v, 4); };
  put(0, kGlbMagic);
  put(4, 2);
  put(8, static_cast<std::uint32_t>(total));
  put(12, static_cast<std::uint32_t>(text.size()));
  put(16, kJsonChunk);
  std::memcpy(glb.data() + 20, text.data(), text.size());
  put(20 + text.size(), static_cast<std::uint32_t>(bin.size()));
  put(24 + text.size(), kBinChunk);
  std::memcpy(glb.data() + 28 + text.size(), bin.data(), bin.size());
  return glb;
}

void writeSplatGlb(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud,
                   const GltfSplatOptions& options) {
  const std::vector<std::uint8_t> glb = encodeSplatGlb(path, cloud, options);
  writeFileAtomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(glb.data()), static_cast<std::streamsize>(glb.size()));
  });
}

namespace {

// The parsed chunks of a GLB and typed access to its buffer views and accessors.
class GlbReader {
 public:
  GlbReader(std::string path, const std::string& bytes) : path_(std::move(path)) {
    auto word = [&](std::size_t at) {
      std::uint32_t v = 0;
      std::memcpy(&v, bytes.data() + at, 4);
      return v;
    };
    if (bytes.size() < 28 || word(0) != kGlbMagic) {
      throw Error(path_, "header", "a binary glTF (magic \"glTF\", at least 28 bytes)",
                  std::to_string(bytes.size()) + " bytes without it");
    }
    if (word(4) != 2) throw Error(path_, "header version", "2", std::to_string(word(4)));
    if (word(8) != bytes.size()) {
      throw Error(path_, "header length", std::to_string(bytes.size()) + " (the file's size)",
                  std::to_string(word(8)));
    }
    const std::size_t json_length = word(12);
    if (word(16) != kJsonChunk || 20 + json_length > bytes.size()) {
      throw Error(path_, "chunk 0", "a JSON chunk inside the file", "another chunk or size");
    }
    try {
      gltf_ = json::parse(bytes.substr(20, json_length));
    } catch (const json::exception& e) {
      throw Error(path_, "JSON chunk", "valid JSON", e.what());
    }
    const std::size_t at = 20 + json_length;
    if (at + 8 <= bytes.size()) {
      const std::size_t length = word(at);
      if (word(at + 4) != kBinChunk || at + 8 + length > bytes.size()) {
        throw Error(path_, "chunk 1", "a BIN chunk inside the file", "another chunk or size");
      }
      bin_ = bytes.substr(at + 8, length);
    }
  }
  const json& gltf() const { return gltf_; }
  // The bytes of buffer view `index`.
  std::string view(const json& index, const std::string& what) const {
    if (!index.is_number_unsigned() || !gltf_.contains("bufferViews") ||
        index.get<std::size_t>() >= gltf_["bufferViews"].size()) {
      throw Error(path_, what + " bufferView", "an index into bufferViews", index.dump());
    }
    const json& v = gltf_["bufferViews"][index.get<std::size_t>()];
    const std::size_t offset = v.value("byteOffset", std::size_t{0});
    const std::size_t length = v.value("byteLength", std::size_t{0});
    if (v.value("buffer", 0) != 0 || offset + length > bin_.size()) {
      throw Error(path_, what + " bufferView", "a range of the BIN chunk",
                  std::to_string(offset) + "+" + std::to_string(length));
    }
    return bin_.substr(offset, length);
  }
  // Accessor `index` as floats (float components, `components` per element, `count` elements).
  template <typename T>
  std::vector<T> values(const json& index, const std::string& semantic, int component,
                        std::size_t per_element, std::size_t count) const {
    const json& accessors = gltf_.at("accessors");
    if (!index.is_number_unsigned() || index.get<std::size_t>() >= accessors.size()) {
      throw Error(path_, semantic, "an accessor index", index.dump());
    }
    const json& a = accessors[index.get<std::size_t>()];
    if (a.value("componentType", 0) != component || a.value("count", std::size_t{0}) != count ||
        !a.contains("bufferView") || a.contains("byteStride")) {
      throw Error(path_, semantic + " accessor",
                  "componentType " + std::to_string(component) + ", count " +
                      std::to_string(count) + ", a tightly packed bufferView",
                  a.dump().substr(0, 120));
    }
    const std::string bytes = view(a["bufferView"], semantic);
    const std::size_t offset = a.value("byteOffset", std::size_t{0});
    const std::size_t need = count * per_element * sizeof(T);
    if (offset + need > bytes.size()) {
      throw Error(path_, semantic + " accessor", std::to_string(need) + " bytes in its view",
                  std::to_string(bytes.size() - std::min(offset, bytes.size())));
    }
    std::vector<T> out(count * per_element);
    std::memcpy(out.data(), bytes.data() + offset, need);
    return out;
  }

 private:
  std::string path_;
  json gltf_;
  std::string bin_;
};

}  // namespace

namespace {

// readSplatGlb's work; json::exception (a missing or mistyped field) is turned into an Error there.
pcl::PointCloud<GaussianPoint> readSplatGlbFields(const std::string& path, GltfSplatInfo* info) {
  const GlbReader glb(path, readWholeFile(path));
  const json& gltf = glb.gltf();
  const json* primitive = nullptr;
  try {
    primitive = &gltf.at("meshes").at(0).at("primitives").at(0);
  } catch (const json::exception&) {
    throw Error(path, "meshes[0].primitives[0]", "a primitive", "none");
  }
  if (!primitive->contains("extensions") || !primitive->at("extensions").contains(kSplat)) {
    throw Error(path, "primitive extensions", kSplat, "missing (not Gaussian splats)");
  }
  const json& attributes = primitive->at("attributes");
  if (!attributes.contains("POSITION")) {
    throw Error(path, "attribute POSITION", "present", "missing");
  }
  const std::size_t n = gltf.at("accessors").at(attributes.at("POSITION").get<std::size_t>()).at("count");
  int degree = 0;
  while (degree < kMaxShDegree && attributes.contains(shName(degree + 1, 0))) ++degree;
  const json& splat = primitive->at("extensions").at(kSplat);
  const bool spz = splat.contains("extensions") && splat.at("extensions").contains(kSpz);
  pcl::PointCloud<GaussianPoint> cloud;
  if (spz) {
    SpzFileInfo spz_info;
    cloud = decodeSpz(path, glb.view(splat.at("extensions").at(kSpz).at("bufferView"), kSpz), &spz_info,
                      true);
    if (cloud.size() != n) {
      throw Error(path, "SPZ payload", std::to_string(n) + " Gaussians (POSITION's count)",
                  std::to_string(cloud.size()));
    }
  } else {
    auto floats = [&](const std::string& semantic, std::size_t per) {
      if (!attributes.contains(semantic)) throw Error(path, "attribute " + semantic, "present", "missing");
      return glb.values<float>(attributes.at(semantic), semantic, kFloat, per, n);
    };
    const std::vector<float> position = floats("POSITION", 3);
    const std::vector<float> rotation = floats(std::string(kPrefix) + "ROTATION", 4);
    const std::vector<float> scale = floats(std::string(kPrefix) + "SCALE", 3);
    const std::vector<float> opacity = floats(std::string(kPrefix) + "OPACITY", 1);
    const std::vector<float> dc = floats(shName(0, 0), 3);
    cloud.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      GaussianPoint& p = cloud[i];
      p.x = position[3 * i];
      p.y = position[3 * i + 1];
      p.z = position[3 * i + 2];
      for (int k = 0; k < 3; ++k) {
        if (!(scale[3 * i + k] > 0)) {
          throw Error(path, "SCALE of splat " + std::to_string(i), "positive (linear scales)",
                      std::to_string(scale[3 * i + k]));
        }
        p.scale[k] = std::log(scale[3 * i + k]);
        p.f_dc[k] = dc[3 * i + k];
      }
      p.rot[0] = rotation[4 * i + 3];
      for (int k = 0; k < 3; ++k) p.rot[k + 1] = rotation[4 * i + k];
      p.opacity = logitOfAlpha(opacity[i]);
    }
    for (int l = 1; l <= degree; ++l) {
      for (int c = 0; c < 2 * l + 1; ++c) {
        const std::vector<float> v = floats(shName(l, c), 3);
        for (std::size_t i = 0; i < n; ++i) {
          for (int ch = 0; ch < 3; ++ch) {
            cloud[i].f_rest[ch * kShRestPerChannel + shRestStart(l) + c] = v[3 * i + ch];
          }
        }
      }
    }
    finishCloud(cloud);
  }
  GltfSplatInfo result;
  if (attributes.contains("_FEATURE_ID_0")) {
    const std::vector<float> ids =
        glb.values<float>(attributes.at("_FEATURE_ID_0"), "_FEATURE_ID_0", kFloat, 1, n);
    for (std::size_t i = 0; i < n; ++i) {
      if (!(ids[i] >= 0 && ids[i] <= kNullFeature) || ids[i] != std::floor(ids[i])) {
        throw Error(path, "_FEATURE_ID_0 of splat " + std::to_string(i), "a whole number 0..65535",
                    std::to_string(ids[i]));
      }
      const auto id = static_cast<std::uint32_t>(ids[i]);
      cloud[i].label = id == kNullFeature ? kUnlabelled : id;
    }
    const json& table = gltf.at("extensions").at("EXT_structural_metadata").at("propertyTables").at(0);
    const std::size_t classes = table.at("count");
    const json& names = table.at("properties").at("name");
    const std::string text = glb.view(names.at("values"), "class names");
    const std::string offsets_bytes = glb.view(names.at("stringOffsets"), "class name offsets");
    if (offsets_bytes.size() < 4 * (classes + 1)) {
      throw Error(path, "class name offsets", std::to_string(classes + 1) + " UINT32",
                  std::to_string(offsets_bytes.size()) + " bytes");
    }
    std::vector<std::uint32_t> offsets(classes + 1);
    std::memcpy(offsets.data(), offsets_bytes.data(), 4 * (classes + 1));
    for (std::size_t c = 0; c < classes; ++c) {
      if (offsets[c] > offsets[c + 1] || offsets[c + 1] > text.size()) {
        throw Error(path, "class name offsets", "increasing offsets into the names", "out of range");
      }
      result.class_names.push_back(text.substr(offsets[c], offsets[c + 1] - offsets[c]));
    }
  }
  const GaussianReadReport report = checkReadGaussians(path, cloud);
  (void)report;
  if (info != nullptr) {
    result.spz = spz;
    result.sh_degree = degree;
    result.count = n;
    for (const auto& e : gltf.value("extensionsUsed", json::array())) result.extensions_used.push_back(e);
    *info = result;
  }
  return cloud;
}

}  // namespace

pcl::PointCloud<GaussianPoint> readSplatGlb(const std::string& path, GltfSplatInfo* info) {
  try {
    return readSplatGlbFields(path, info);
  } catch (const json::exception& e) {
    throw Error(path, "glTF JSON", "the fields and types of a glTF of Gaussian splats", e.what());
  }
}

}  // namespace io
}  // namespace sadsplat
