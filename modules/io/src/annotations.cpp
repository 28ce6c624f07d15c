#include "sadsplat/io/annotations.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"

namespace sadsplat {
namespace io {
namespace {

using nlohmann::json;

std::string baseName(const std::string& path) {
  std::string p = path;
  std::replace(p.begin(), p.end(), '\\', '/');  // LabelMe on Windows writes "..\\images\\a.jpg"
  const auto slash = p.find_last_of('/');
  return slash == std::string::npos ? p : p.substr(slash + 1);
}

json parseFile(const std::string& path) {
  try {
    return json::parse(readWholeFile(path));
  } catch (const json::exception& e) {
    throw Error(path, "JSON syntax", "valid JSON", e.what());
  }
}

double number(const json& v, const std::string& path, const std::string& field) {
  if (!v.is_number()) throw Error(path, field, "a number", v.dump().substr(0, 40));
  const double x = v.get<double>();
  if (!std::isfinite(x)) throw Error(path, field, "a finite number", v.dump());
  return x;
}

int positiveInt(const json& obj, const char* key, const std::string& path,
                const std::string& field) {
  if (!obj.contains(key)) throw Error(path, field, "a positive integer", "missing");
  const double v = number(obj.at(key), path, field);
  if (!(v >= 1 && v <= 1e6) || v != std::floor(v)) {
    throw Error(path, field, "a positive integer up to 1000000", obj.at(key).dump());
  }
  return static_cast<int>(v);
}

std::string text(const json& obj, const char* key, const std::string& path,
                 const std::string& field) {
  if (!obj.contains(key) || !obj.at(key).is_string()) {
    throw Error(path, field, "a string", obj.contains(key) ? obj.at(key).dump().substr(0, 40) : "missing");
  }
  return obj.at(key).get<std::string>();
}

AnnotatedImage readLabelMe(const json& j, const std::string& path, int* skipped) {
  AnnotatedImage image;
  image.file_name = baseName(text(j, "imagePath", path, "imagePath"));
  image.width = positiveInt(j, "imageWidth", path, "imageWidth");
  image.height = positiveInt(j, "imageHeight", path, "imageHeight");
  if (!j.at("shapes").is_array()) throw Error(path, "shapes", "an array", j.at("shapes").type_name());
  int index = 0;
  for (const json& s : j.at("shapes")) {
    const std::string field = "shapes[" + std::to_string(index++) + "]";
    if (!s.is_object()) throw Error(path, field, "an object", s.type_name());
    const std::string type = s.value("shape_type", std::string("polygon"));
    AnnotatedShape shape;
    shape.label = text(s, "label", path, field + ".label");
    if (!s.contains("points") || !s.at("points").is_array()) {
      throw Error(path, field + ".points", "an array of [x, y]", "missing");
    }
    std::vector<std::array<double, 2>> ring;
    int p = 0;
    for (const json& xy : s.at("points")) {
      const std::string pf = field + ".points[" + std::to_string(p++) + "]";
      if (!xy.is_array() || xy.size() != 2) throw Error(path, pf, "[x, y]", xy.dump().substr(0, 40));
      ring.push_back({number(xy[0], path, pf), number(xy[1], path, pf)});
    }
    if (type == "rectangle") {
      if (ring.size() != 2) {
        throw Error(path, field + ".points", "2 corners of a rectangle", std::to_string(ring.size()));
      }
      const auto a = ring[0], b = ring[1];
      ring = {a, {b[0], a[1]}, b, {a[0], b[1]}};
    } else if (type == "polygon") {
      if (ring.size() < 3) {
        throw Error(path, field + ".points", "at least 3 points of a polygon",
                    std::to_string(ring.size()));
      }
    } else {
      if (skipped) ++*skipped;  // point, line, linestrip, circle: no area to label
      continue;
    }
    shape.polygons.push_back(std::move(ring));
    image.shapes.push_back(std::move(shape));
  }
  return image;
}

std::vector<AnnotatedImage> readCoco(const json& j, const std::string& path) {
  for (const char* key : {"images", "annotations", "categories"}) {
    if (!j.at(key).is_array()) throw Error(path, key, "an array", j.at(key).type_name());
  }
  std::map<long long, std::string> categories;
  for (const json& c : j.at("categories")) {
    categories[static_cast<long long>(number(c.at("id"), path, "categories[].id"))] =
        text(c, "name", path, "categories[].name");
  }
  std::map<long long, std::size_t> image_index;
  std::vector<AnnotatedImage> images;
  for (const json& im : j.at("images")) {
    AnnotatedImage a;
    a.file_name = baseName(text(im, "file_name", path, "images[].file_name"));
    a.width = positiveInt(im, "width", path, "images[" + a.file_name + "].width");
    a.height = positiveInt(im, "height", path, "images[" + a.file_name + "].height");
    image_index[static_cast<long long>(number(im.at("id"), path, "images[].id"))] = images.size();
    images.push_back(std::move(a));
  }
  int index = 0;
  for (const json& an : j.at("annotations")) {
    const std::string field = "annotations[" + std::to_string(index++) + "]";
    const long long image_id =
        static_cast<long long>(number(an.at("image_id"), path, field + ".image_id"));
    const long long category_id =
        static_cast<long long>(number(an.at("category_id"), path, field + ".category_id"));
    const auto im = image_index.find(image_id);
    if (im == image_index.end()) {
      throw Error(path, field + ".image_id", "the id of an entry of images", std::to_string(image_id));
    }
    const auto cat = categories.find(category_id);
    if (cat == categories.end()) {
      throw Error(path, field + ".category_id", "the id of an entry of categories",
                  std::to_string(category_id));
    }
    AnnotatedImage& image = images[im->second];
    AnnotatedShape shape;
    shape.label = cat->second;
    if (!an.contains("segmentation")) throw Error(path, field + ".segmentation", "polygons or an RLE", "missing");
    const json& seg = an.at("segmentation");
    if (seg.is_array()) {
      for (const json& poly : seg) {
        if (!poly.is_array() || poly.size() < 6 || poly.size() % 2 != 0) {
          throw Error(path, field + ".segmentation", "polygons [x1, y1, x2, y2, ...] of >= 3 points",
                      poly.dump().substr(0, 40));
        }
        std::vector<std::array<double, 2>> ring;
        for (std::size_t k = 0; k < poly.size(); k += 2) {
          ring.push_back({number(poly[k], path, field + ".segmentation"),
                          number(poly[k + 1], path, field + ".segmentation")});
        }
        shape.polygons.push_back(std::move(ring));
      }
    } else if (seg.is_object()) {
      const json& size = seg.at("size");
      if (!size.is_array() || size.size() != 2) {
        throw Error(path, field + ".segmentation.size", "[height, width]", size.dump());
      }
      const int h = static_cast<int>(number(size[0], path, field + ".segmentation.size"));
      const int w = static_cast<int>(number(size[1], path, field + ".segmentation.size"));
      if (h != image.height || w != image.width) {
        throw Error(path, field + ".segmentation.size",
                    "the image's [" + std::to_string(image.height) + ", " +
                        std::to_string(image.width) + "]",
                    size.dump());
      }
      std::vector<std::uint32_t> counts;
      const json& c = seg.at("counts");
      if (c.is_string()) {
        counts = cocoRleCounts(c.get<std::string>(), path + " (" + field + ")");
      } else if (c.is_array()) {
        for (const json& v : c) {
          const double x = number(v, path, field + ".segmentation.counts");
          if (x < 0 || x != std::floor(x)) {
            throw Error(path, field + ".segmentation.counts", "non-negative integers", v.dump());
          }
          counts.push_back(static_cast<std::uint32_t>(x));
        }
      } else {
        throw Error(path, field + ".segmentation.counts", "a list or a string", c.type_name());
      }
      shape.mask = decodeCocoRle(counts, h, w, path + " (" + field + ")");
    } else {
      throw Error(path, field + ".segmentation", "polygons or an RLE", seg.type_name());
    }
    image.shapes.push_back(std::move(shape));
  }
  return images;
}

}  // namespace

std::vector<std::uint32_t> cocoRleCounts(const std::string& s, const std::string& origin) {
  // pycocotools' rleFrString: 5 bits per character from 48, a continuation bit 0x20, the last
  // character's 0x10 the sign; from the third run on, a run is stored as the difference to the
  // run two before.
  std::vector<long long> counts;
  std::size_t p = 0;
  while (p < s.size()) {
    long long x = 0;
    int k = 0;
    bool more = true;
    while (more) {
      if (p >= s.size() || k > 12) {
        throw Error(origin, "segmentation.counts", "a complete COCO RLE string", "a cut-off run");
      }
      const long long c = static_cast<long long>(static_cast<unsigned char>(s[p])) - 48;
      if (c < 0 || c > 63) throw Error(origin, "segmentation.counts", "characters '0'..'o'", s.substr(p, 1));
      x |= (c & 0x1f) << (5 * k);
      more = (c & 0x20) != 0;
      ++p;
      ++k;
      // The sign bit set: the k * 5-bit value is negative (x - 2^(5k); no shift of a negative).
      if (!more && (c & 0x10)) x -= 1LL << (5 * k);
    }
    if (counts.size() > 2) x += counts[counts.size() - 2];
    if (x < 0) throw Error(origin, "segmentation.counts", "non-negative runs", std::to_string(x));
    counts.push_back(x);
  }
  return std::vector<std::uint32_t>(counts.begin(), counts.end());
}

std::vector<std::uint8_t> decodeCocoRle(const std::vector<std::uint32_t>& counts, int height,
                                        int width, const std::string& origin) {
  const std::size_t n = static_cast<std::size_t>(height) * width;
  std::vector<std::uint8_t> mask(n, 0);
  std::size_t at = 0;
  std::uint8_t value = 0;
  for (std::uint32_t run : counts) {
    if (run > n - at) {
      throw Error(origin, "segmentation.counts", "runs adding up to " + std::to_string(n) + " pixels",
                  "more");
    }
    for (std::size_t i = at; i < at + run; ++i) {
      // Column-major in COCO: run index i is pixel (x = i / height, y = i % height).
      mask[(i % height) * static_cast<std::size_t>(width) + i / height] = value;
    }
    at += run;
    value ^= 1;
  }
  if (at != n) {
    throw Error(origin, "segmentation.counts", "runs adding up to " + std::to_string(n) + " pixels",
                std::to_string(at));
  }
  return mask;
}

std::vector<AnnotatedImage> readAnnotations(const std::string& path, int* skipped) {
  if (skipped) *skipped = 0;
  if (isDirectory(path)) {
    std::vector<std::string> files =
        filesIn(path, [](const std::string& name) { return lowerExtension(name) == ".json"; });
    for (auto& f : files) f = path + "/" + f;
    if (files.empty()) throw Error(path, "annotations", "LabelMe .json files", "none");
    std::vector<AnnotatedImage> images;
    for (const auto& f : files) {
      const json j = parseFile(f);
      // Other JSON files in the folder (a classes.json) are not annotations.
      if (!j.is_object() || !j.contains("shapes")) continue;
      images.push_back(readLabelMe(j, f, skipped));
    }
    if (images.empty()) {
      throw Error(path, "annotations", "LabelMe .json files (objects with \"shapes\")", "none");
    }
    return images;
  }
  requireRegularFile(path);
  const json j = parseFile(path);
  if (j.is_object() && j.contains("shapes")) return {readLabelMe(j, path, skipped)};
  if (j.is_object() && j.contains("images") && j.contains("annotations") && j.contains("categories")) {
    return readCoco(j, path);
  }
  throw Error(path, "annotations",
              "LabelMe (an object with \"shapes\") or COCO (\"images\", \"annotations\", \"categories\")",
              j.is_object() ? "neither" : j.type_name());
}

}  // namespace io
}  // namespace sadsplat
