#include "sadsplat/io/scene_cache.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <functional>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/image_file.h"
#include "parallel_jobs.h"
#include "plane_codec.h"

namespace sadsplat {
namespace io {
namespace {

constexpr char kSceneMagic[8] = {'S', 'A', 'D', 'S', 'C', 'E', 'N', 'E'};
constexpr std::size_t kHeaderSize = 8 + 4 + 4 + 8 + 8;

// Little-endian writer into a byte string (x86-64 and ARM hosts are little endian).
class ByteWriter {
 public:
  template <typename T>
  void put(const T& v) {
    bytes_.append(reinterpret_cast<const char*>(&v), sizeof(T));
  }
  void putString(const std::string& s) {
    put<std::uint32_t>(static_cast<std::uint32_t>(s.size()));
    bytes_.append(s);
  }
  template <typename T>
  void putArray(const std::vector<T>& v) {
    bytes_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  void putBytes(const std::vector<std::uint8_t>& v) {
    bytes_.append(reinterpret_cast<const char*>(v.data()), v.size());
  }
  // A block: u64 byte count, the bytes.
  void putBlock(const std::vector<std::uint8_t>& v) {
    put<std::uint64_t>(v.size());
    putBytes(v);
  }
  // Chunk: 4-byte tag, u64 size, content.
  void putChunk(const char tag[4], const ByteWriter& content) {
    bytes_.append(tag, 4);
    put<std::uint64_t>(content.bytes_.size());
    bytes_.append(content.bytes_);
  }
  const std::string& bytes() const { return bytes_; }

 private:
  std::string bytes_;
};

class ByteReader {
 public:
  ByteReader(const std::string& path, const char* data, std::size_t size, std::string context)
      : path_(path), data_(data), size_(size), context_(std::move(context)) {}

  template <typename T>
  T get(const char* field) {
    need(sizeof(T), field);
    T v;
    std::memcpy(&v, data_ + pos_, sizeof(T));
    pos_ += sizeof(T);
    return v;
  }
  double getFinite(const char* field) {
    const double v = get<double>(field);
    if (!std::isfinite(v))
      throw Error(path_, context_ + " " + field, "a finite number", std::to_string(v));
    return v;
  }
  std::string getString(const char* field) {
    const auto n = get<std::uint32_t>(field);
    need(n, field);
    std::string s(data_ + pos_, n);
    pos_ += n;
    return s;
  }
  std::vector<std::uint8_t> getBytes(std::size_t n, const char* field) {
    need(n, field);
    std::vector<std::uint8_t> v(reinterpret_cast<const std::uint8_t*>(data_ + pos_),
                                reinterpret_cast<const std::uint8_t*>(data_ + pos_ + n));
    pos_ += n;
    return v;
  }
  template <typename T>
  std::vector<T> getArray(std::size_t n, const char* field) {
    if (n > remaining() / sizeof(T)) need(remaining() + 1, field);
    std::vector<T> v(n);
    if (n > 0)
      std::memcpy(v.data(), data_ + pos_, n * sizeof(T));  // data() of an empty vector is null
    pos_ += n * sizeof(T);
    return v;
  }
  // A block written by ByteWriter::putBlock: its bytes, in place.
  std::pair<const std::uint8_t*, std::size_t> getBlock(const char* field) {
    const auto n = get<std::uint64_t>(field);
    need(n, field);
    const auto* begin = reinterpret_cast<const std::uint8_t*>(data_ + pos_);
    pos_ += n;
    return {begin, static_cast<std::size_t>(n)};
  }
  ByteReader subReader(std::size_t n, const std::string& context) {
    need(n, "chunk");
    ByteReader sub(path_, data_ + pos_, n, context);
    pos_ += n;
    return sub;
  }
  bool atEnd() const { return pos_ == size_; }
  const std::string& path() const { return path_; }
  std::size_t remaining() const { return size_ - pos_; }
  const std::string& context() const { return context_; }

 private:
  void need(std::size_t n, const char* field) const {
    if (n > size_ - pos_) {
      throw Error(path_, context_ + " " + field, "more data (file is truncated or corrupt)",
                  std::to_string(size_ - pos_) + " bytes left");
    }
  }
  const std::string& path_;
  const char* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
  std::string context_;
};

// Every label of a view a class id of the scene or 255 (ignore).
void checkLabels(const std::string& path, const View& v, std::size_t classes) {
  for (std::size_t i = 0; i < v.labels.pixels.size(); ++i) {
    const auto l = v.labels.pixels[i];
    if (l != kIgnoreLabel && l >= classes) {
      throw Error(path, "view " + v.name + " label pixel " + std::to_string(i),
                  "a class id below " + std::to_string(classes) + " or 255", std::to_string(l));
    }
  }
}

Image8 readImage(ByteReader& r, std::uint32_t version, int w, int h, int channels,
                 const char* field) {
  if (version >= 3) {
    const auto [data, size] = r.getBlock(field);
    return planes::decodeImage(r.path(), r.context() + " " + field, data, size, w, h, channels);
  }
  Image8 image;
  image.width = w;
  image.height = h;
  image.channels = channels;
  image.pixels = r.getBytes(static_cast<std::size_t>(w) * h * channels, field);
  return image;
}

// The scene's classes (chunk CLAS).
std::vector<ClassInfo> readClassChunk(ByteReader& c, const std::string& path) {
  const auto n = c.get<std::uint32_t>("class count");
  // Label maps are bytes with 255 = ignore: at most 255 classes (as classes.json); 0 is a scene
  // without classes (plain 3DGS).
  if (n > 255) throw Error(path, "chunk CLAS class count", "0 to 255 classes", std::to_string(n));
  std::vector<ClassInfo> classes;
  for (std::uint32_t i = 0; i < n; ++i) {
    ClassInfo cls;
    cls.name = c.getString("class name");
    for (auto& v : cls.color) v = c.get<std::uint8_t>("class colour");
    cls.prompt = c.getString("class prompt");
    classes.push_back(cls);
  }
  return classes;
}

// A VIEW chunk up to its images: name, camera (checked) and roles; `has_labels` whether a label
// map follows the mask (which needs the classes read before: `classes_read`).
View readViewHead(ByteReader& c, const std::string& path, bool classes_read, bool* has_labels) {
  View v;
  v.name = c.getString("view name");
  v.camera.width = static_cast<int>(c.get<std::uint32_t>("width"));
  v.camera.height = static_cast<int>(c.get<std::uint32_t>("height"));
  v.camera.fx = c.getFinite("fx");
  v.camera.fy = c.getFinite("fy");
  v.camera.cx = c.getFinite("cx");
  v.camera.cy = c.getFinite("cy");
  for (double& q : v.camera.qvec) q = c.getFinite("qvec");
  for (double& t : v.camera.tvec) t = c.getFinite("tvec");
  const auto roles = c.get<std::uint8_t>("roles");
  v.train = roles & 1;
  v.test = roles & 2;
  v.labelled = roles & 4;
  *has_labels = c.get<std::uint8_t>("has labels") != 0;
  v.camera.validate(path, "view " + v.name + " camera");
  if (*has_labels && !classes_read) {
    throw Error(path, "chunk order", "CLAS before VIEW", "VIEW " + v.name + " first");
  }
  return v;
}

// The sparse points (chunk PNTS).
std::vector<ScenePoint> readPointChunk(ByteReader& c, const std::string& path) {
  const auto n = c.get<std::uint64_t>("point count");
  if (n > c.remaining() / 15) {
    throw Error(path, "chunk PNTS point count", "a count that fits the chunk", std::to_string(n));
  }
  std::vector<ScenePoint> points(n);
  for (auto& p : points) {
    for (float& x : p.xyz) {
      x = c.get<float>("point xyz");
      if (!std::isfinite(x)) {
        throw Error(path, "point xyz", "finite coordinates", std::to_string(x));
      }
    }
    for (auto& v : p.rgb) v = c.get<std::uint8_t>("point rgb");
  }
  return points;
}

// The start of a PSLB chunk: the name of its view, which must be `previous` (the view read just
// before the chunk; null: none).
View& pseudoChunkView(ByteReader& c, View* previous, const std::string& path) {
  const std::string name = c.getString("view name");
  if (previous == nullptr || previous->name != name) {
    throw Error(path, "chunk PSLB view", "the view read just before it", name);
  }
  return *previous;
}

// The rest of a PSLB chunk (after pseudoChunkView) into `view.pseudo`, but for a version-3 region
// map: its deflated block, returned for finishPseudoLabels (null for versions 1-2, whose raw map
// is read here).
std::pair<const std::uint8_t*, std::size_t> readPseudoChunk(ByteReader& c, std::uint32_t version,
                                                            std::size_t classes, View& view,
                                                            const std::string& path) {
  const std::string& name = view.name;
  ViewPseudoLabels& p = view.pseudo;
  p.backend = c.getString("backend");
  p.num_targets = static_cast<int>(c.get<std::uint32_t>("target count"));
  p.num_classes = static_cast<int>(c.get<std::uint32_t>("class count"));
  p.feature_dim = static_cast<int>(c.get<std::uint32_t>("feature dim"));
  const std::size_t pixels = static_cast<std::size_t>(view.camera.width) * view.camera.height;
  std::pair<const std::uint8_t*, std::size_t> region_block{nullptr, 0};
  if (version >= 3) {
    region_block = c.getBlock("region map");
  } else {
    p.region = c.getArray<std::int32_t>(pixels, "region map");
  }
  p.scores = c.getArray<float>(static_cast<std::size_t>(p.num_targets) * p.num_classes, "scores");
  p.features =
      c.getArray<float>(static_cast<std::size_t>(p.num_targets) * p.feature_dim, "features");
  p.kept = c.getBytes(p.num_targets, "kept flags");
  if (p.num_classes != static_cast<int>(classes)) {
    throw Error(path, "view " + name + " pseudo-labels class count", std::to_string(classes),
                std::to_string(p.num_classes));
  }
  return region_block;
}

// The region map of `view`'s pseudo-labels from its block (if any), then their checks.
void finishPseudoLabels(View& view, std::pair<const std::uint8_t*, std::size_t> region_block,
                        const std::string& path) {
  const std::size_t pixels = static_cast<std::size_t>(view.camera.width) * view.camera.height;
  if (region_block.first != nullptr) {
    view.pseudo.region =
        planes::decodeRegions(path, "chunk PSLB region map of view " + view.name,
                              region_block.first, region_block.second, pixels, view.camera.width);
  }
  view.pseudo.validate(path + " (view " + view.name + ")", pixels);
}

// The chunks about the whole scene (SRCE, CLAS, PNTS, GEOR) into `scene`; false for any other tag.
bool readSceneChunk(const std::string& tag, ByteReader& c, const std::string& path, Scene& scene,
                    bool* have_classes) {
  if (tag == "SRCE") {
    scene.source = c.getString("source");
  } else if (tag == "CLAS") {
    scene.classes = readClassChunk(c, path);
    *have_classes = true;
  } else if (tag == "PNTS") {
    scene.points = readPointChunk(c, path);
  } else if (tag == "GEOR") {
    scene.georeference = georeferenceFromJson(c.getString("georeference"), path + " (GEOR)");
  } else {
    return false;
  }
  return true;
}

}  // namespace

namespace {

std::uint64_t fnv1aWithBasis(const void* data, std::size_t size, std::uint64_t basis) {
  const auto* p = static_cast<const unsigned char*>(data);
  std::uint64_t hash = basis;
  for (std::size_t i = 0; i < size; ++i) {
    hash ^= p[i];
    hash *= 1099511628211ull;
  }
  return hash;
}

// Version 1 files were written with an offset basis one digit short of FNV-1a-64's
// (1469598103934665603 instead of 14695981039346656037); they stay readable.
constexpr std::uint64_t kVersion1Basis = 1469598103934665603ull;

}  // namespace

std::uint64_t fnv1a64(const void* data, std::size_t size) {
  return fnv1aWithBasis(data, size, 14695981039346656037ull);
}

void writeSceneCache(const std::string& path, const Scene& scene) {
  ByteWriter payload;
  {
    ByteWriter c;
    c.putString(scene.source);
    payload.putChunk("SRCE", c);
  }
  {
    ByteWriter c;
    c.put<std::uint32_t>(static_cast<std::uint32_t>(scene.classes.size()));
    for (const auto& cls : scene.classes) {
      c.putString(cls.name);
      for (auto v : cls.color) c.put<std::uint8_t>(v);
      c.putString(cls.prompt);
    }
    payload.putChunk("CLAS", c);
  }
  for (const View& v : scene.views) {
    const auto pixels = static_cast<std::size_t>(v.camera.width) * v.camera.height;
    if (v.rgb.pixels.size() != pixels * 3 || v.mask.pixels.size() != pixels ||
        (!v.labels.empty() && v.labels.pixels.size() != pixels)) {
      throw Error(path, "view " + v.name,
                  "images of the camera's size " + std::to_string(v.camera.width) + "x" +
                      std::to_string(v.camera.height),
                  "an image with another pixel count");
    }
    ByteWriter c;
    c.putString(v.name);
    c.put<std::uint32_t>(v.camera.width);
    c.put<std::uint32_t>(v.camera.height);
    for (double x : {v.camera.fx, v.camera.fy, v.camera.cx, v.camera.cy}) c.put<double>(x);
    for (double q : v.camera.qvec) c.put<double>(q);
    for (double t : v.camera.tvec) c.put<double>(t);
    const std::uint8_t roles = (v.train ? 1 : 0) | (v.test ? 2 : 0) | (v.labelled ? 4 : 0);
    c.put<std::uint8_t>(roles);
    c.put<std::uint8_t>(v.labels.empty() ? 0 : 1);
    // Version 3: each image as deflated prediction residuals (plane_codec.h), its size first.
    for (const Image8* image : {&v.rgb, &v.mask, &v.labels}) {
      if (image->empty()) continue;
      c.putBlock(planes::encodeImage(path, *image));
    }
    payload.putChunk("VIEW", c);
    if (!v.pseudo.empty()) {
      // Pseudo-labels follow their view as a chunk of their own, so readers that predate them
      // skip them (the format version stays 1).
      const ViewPseudoLabels& p = v.pseudo;
      p.validate(path + " (view " + v.name + ")", pixels);
      ByteWriter q;
      q.putString(v.name);
      q.putString(p.backend);
      q.put<std::uint32_t>(static_cast<std::uint32_t>(p.num_targets));
      q.put<std::uint32_t>(static_cast<std::uint32_t>(p.num_classes));
      q.put<std::uint32_t>(static_cast<std::uint32_t>(p.feature_dim));
      q.putBlock(planes::encodeRegions(path, p.region, v.camera.width));
      q.putArray(p.scores);
      q.putArray(p.features);
      q.putBytes(p.kept);
      payload.putChunk("PSLB", q);
    }
  }
  {
    ByteWriter c;
    c.put<std::uint64_t>(scene.points.size());
    for (const auto& p : scene.points) {
      for (float x : p.xyz) c.put<float>(x);
      for (auto v : p.rgb) c.put<std::uint8_t>(v);
    }
    payload.putChunk("PNTS", c);
  }
  if (scene.georeference) {
    // Older readers skip the chunk (unknown chunks are skipped): the version stays.
    ByteWriter c;
    c.putString(georeferenceToJson(*scene.georeference));
    payload.putChunk("GEOR", c);
  }
  const std::string& body = payload.bytes();
  ByteWriter header;
  for (char ch : kSceneMagic) header.put<char>(ch);
  header.put<std::uint32_t>(kSceneCacheVersion);
  header.put<std::uint32_t>(0);  // flags, reserved
  header.put<std::uint64_t>(body.size());
  header.put<std::uint64_t>(fnv1a64(body.data(), body.size()));
  writeFileAtomically(path, [&](std::ostream& out) {
    out.write(header.bytes().data(), static_cast<std::streamsize>(header.bytes().size()));
    out.write(body.data(), static_cast<std::streamsize>(body.size()));
  });
}

bool isSceneCache(const std::string& path) {
  if (!isRegularFile(path)) return false;  // a FIFO would block the read below
  std::ifstream in(path, std::ios::binary);
  char magic[8] = {};
  return in.read(magic, 8) && std::memcmp(magic, kSceneMagic, 8) == 0;
}

std::uint32_t sceneCacheVersion(const std::string& path) {
  const std::string head = readFileStart(path, 12);
  if (head.size() < 12 || std::memcmp(head.data(), kSceneMagic, 8) != 0) {
    throw Error(path, "magic", "a sadsplat scene cache starting with \"SADSCENE\"",
                "other bytes");
  }
  std::uint32_t version;
  std::memcpy(&version, head.data() + 8, 4);
  return version;
}

namespace {

struct CacheHeader {
  std::uint32_t version = 0;
  std::uint64_t payload_size = 0;
  std::uint64_t checksum = 0;
};

// The header at the start of `bytes` (at least its first 32 bytes) of a file of `file_size`
// bytes: magic, a version this reader knows, a payload size that matches the file.
CacheHeader readCacheHeader(const std::string& path, const std::string& bytes,
                            std::uint64_t file_size) {
  ByteReader head(path, bytes.data(), bytes.size(), "header");
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kSceneMagic, 8) != 0) {
    throw Error(path, "magic", "a sadsplat scene cache starting with \"SADSCENE\"",
                "other bytes");
  }
  head.getBytes(8, "magic");
  CacheHeader h;
  h.version = head.get<std::uint32_t>("version");
  if (h.version < 1 || h.version > kSceneCacheVersion) {
    throw Error(path, "version",
                "1 to " + std::to_string(kSceneCacheVersion) +
                    " (a newer sadsplat wrote it, or it is damaged: re-import the scene)",
                std::to_string(h.version));
  }
  head.get<std::uint32_t>("flags");
  h.payload_size = head.get<std::uint64_t>("payload size");
  h.checksum = head.get<std::uint64_t>("checksum");
  if (h.payload_size != file_size - kHeaderSize) {
    throw Error(path, "payload size", std::to_string(h.payload_size) + " bytes after the header",
                std::to_string(file_size - kHeaderSize) + " (file truncated or padded)");
  }
  return h;
}

void throwChecksumMismatch(const std::string& path) {
  throw Error(path, "checksum", "the FNV-1a hash stored in the header", "a mismatch (corrupt)");
}

}  // namespace

Scene readSceneCache(const std::string& path) {
  const std::string bytes = readWholeFile(path);
  const CacheHeader header = readCacheHeader(path, bytes, bytes.size());
  const std::uint32_t version = header.version;
  const std::uint64_t payload_size = header.payload_size;
  const char* body = bytes.data() + kHeaderSize;
  const std::uint64_t hash = version == 1 ? fnv1aWithBasis(body, payload_size, kVersion1Basis)
                                          : fnv1a64(body, payload_size);
  if (hash != header.checksum) throwChecksumMismatch(path);

  Scene scene;
  // Version 3's images and region maps are decoded after the chunks are read, on every core
  // (a 1,120-view cache of 1600x900 is ~8 GB of pixels): the jobs, in file order.
  std::vector<std::function<void()>> decoding;
  ByteReader r(path, body, payload_size, "payload");
  bool have_classes = false;
  while (!r.atEnd()) {
    const auto tag_bytes = r.getBytes(4, "chunk tag");
    const std::string tag(tag_bytes.begin(), tag_bytes.end());
    const auto size = r.get<std::uint64_t>("chunk size");
    ByteReader c = r.subReader(size, "chunk " + tag);
    if (readSceneChunk(tag, c, path, scene, &have_classes)) continue;
    if (tag == "VIEW") {
      bool has_labels = false;
      View v = readViewHead(c, path, have_classes, &has_labels);
      const int w = v.camera.width, h = v.camera.height;
      const std::size_t index = scene.views.size();
      // An image: read here (raw planes) or decoded by a job after this pass (version 3).
      const auto image = [&](Image8 View::*member, int channels, const char* field,
                             bool labels) {
        if (version < 3) {
          v.*member = readImage(c, version, w, h, channels, field);
          if (labels) checkLabels(path, v, scene.classes.size());
          return;
        }
        const auto [data, size] = c.getBlock(field);
        const std::string where = c.context() + " " + field;
        decoding.push_back([&scene, &path, index, member, data = data, size = size, where, w,
                            h, channels, labels] {
          View& view = scene.views[index];
          view.*member = planes::decodeImage(path, where, data, size, w, h, channels);
          if (labels) checkLabels(path, view, scene.classes.size());
        });
      };
      image(&View::rgb, 3, "rgb", false);
      image(&View::mask, 1, "mask", false);
      if (has_labels) image(&View::labels, 1, "labels", true);
      scene.views.push_back(std::move(v));
    } else if (tag == "PSLB") {
      View& view =
          pseudoChunkView(c, scene.views.empty() ? nullptr : &scene.views.back(), path);
      const auto region_block = readPseudoChunk(c, version, scene.classes.size(), view, path);
      const std::size_t index = scene.views.size() - 1;
      const auto finish = [&scene, &path, index, region_block] {
        finishPseudoLabels(scene.views[index], region_block, path);
      };
      if (version >= 3) {
        decoding.push_back(finish);
      } else {
        finish();
      }
    }
    // Unknown chunks are skipped: later versions may add chunks readers can ignore.
  }
  if (!have_classes) throw Error(path, "chunk CLAS", "present", "missing");
  runJobsInParallel(decoding);
  return scene;
}

}  // namespace io
}  // namespace sadsplat

namespace sadsplat {
namespace io {

Scene readSceneCacheWithoutPixels(const std::string& path) {
  requireRegularFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "file", "an existing, readable file", "cannot be opened");
  in.seekg(0, std::ios::end);
  const auto file_size = static_cast<std::uint64_t>(in.tellg());
  in.seekg(0);
  std::string head(kHeaderSize, '\0');
  in.read(&head[0], kHeaderSize);
  head.resize(static_cast<std::size_t>(in.gcount()));
  const CacheHeader header = readCacheHeader(path, head, file_size);
  // The payload one chunk at a time, hashed as it is read.
  std::uint64_t hash = header.version == 1 ? kVersion1Basis : 14695981039346656037ull;
  std::uint64_t pos = kHeaderSize;
  std::string buffer;
  const auto readBytes = [&](std::uint64_t n, const char* field) -> const std::string& {
    if (n > file_size - pos) {
      throw Error(path, std::string("payload ") + field,
                  "more data (file is truncated or corrupt)",
                  std::to_string(file_size - pos) + " bytes left");
    }
    buffer.resize(static_cast<std::size_t>(n));
    if (n > 0 && !in.read(&buffer[0], static_cast<std::streamsize>(n))) {
      throw Error(path, field, "readable bytes", "a read error");
    }
    hash = fnv1aWithBasis(buffer.data(), buffer.size(), hash);
    pos += n;
    return buffer;
  };
  Scene scene;
  bool have_classes = false;
  while (pos < file_size) {
    const std::string tag_and_size = readBytes(12, "chunk tag");
    const std::string tag = tag_and_size.substr(0, 4);
    std::uint64_t size;
    std::memcpy(&size, tag_and_size.data() + 4, 8);
    const std::uint64_t offset = pos;
    const std::string& content = readBytes(size, "chunk");
    ByteReader c(path, content.data(), content.size(), "chunk " + tag);
    if (readSceneChunk(tag, c, path, scene, &have_classes)) continue;
    if (tag == "VIEW") {
      auto at = std::make_shared<ViewPixelsInCache>();
      View v = readViewHead(c, path, have_classes, &at->has_labels);
      at->path = path;
      at->version = header.version;
      at->classes = scene.classes.size();
      at->view_offset = offset;
      at->view_size = size;
      v.pixels_in_cache = std::move(at);
      scene.views.push_back(std::move(v));
    } else if (tag == "PSLB") {
      View& v = pseudoChunkView(c, scene.views.empty() ? nullptr : &scene.views.back(), path);
      auto at = std::make_shared<ViewPixelsInCache>(*v.pixels_in_cache);
      at->pseudo_offset = offset;
      at->pseudo_size = size;
      v.pixels_in_cache = std::move(at);
    }
  }
  if (hash != header.checksum) throwChecksumMismatch(path);
  if (!have_classes) throw Error(path, "chunk CLAS", "present", "missing");
  return scene;
}

View readViewPixels(const View& view) {
  if (!view.pixels_in_cache) return view;
  const ViewPixelsInCache& at = *view.pixels_in_cache;
  std::ifstream in(at.path, std::ios::binary);
  const auto chunk = [&](std::uint64_t offset, std::uint64_t size, const char* what) {
    std::string bytes(static_cast<std::size_t>(size), '\0');
    in.seekg(static_cast<std::streamoff>(offset));
    if (!in || !in.read(&bytes[0], static_cast<std::streamsize>(size))) {
      throw Error(at.path, "view " + view.name + " " + what,
                  "the bytes found when the cache was opened", "a shorter file (it changed since)");
    }
    return bytes;
  };
  const std::string view_bytes = chunk(at.view_offset, at.view_size, "VIEW chunk");
  ByteReader c(at.path, view_bytes.data(), view_bytes.size(), "chunk VIEW");
  bool has_labels = false;
  const View head = readViewHead(c, at.path, /*classes_read=*/true, &has_labels);
  if (head.name != view.name || has_labels != at.has_labels) {
    throw Error(at.path, "view " + view.name, "the view found when the cache was opened",
                "view " + head.name + " (the file changed since)");
  }
  View out = view;
  out.pixels_in_cache = nullptr;
  const int w = out.camera.width, h = out.camera.height;
  out.rgb = readImage(c, at.version, w, h, 3, "rgb");
  out.mask = readImage(c, at.version, w, h, 1, "mask");
  if (has_labels) {
    out.labels = readImage(c, at.version, w, h, 1, "labels");
    checkLabels(at.path, out, at.classes);
  }
  if (at.pseudo_size > 0) {
    const std::string pseudo_bytes = chunk(at.pseudo_offset, at.pseudo_size, "PSLB chunk");
    ByteReader q(at.path, pseudo_bytes.data(), pseudo_bytes.size(), "chunk PSLB");
    View& view = pseudoChunkView(q, &out, at.path);
    finishPseudoLabels(view, readPseudoChunk(q, at.version, at.classes, view, at.path), at.path);
  }
  return out;
}

}  // namespace io
}  // namespace sadsplat
