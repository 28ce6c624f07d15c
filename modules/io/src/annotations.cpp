#include "sadsplat/io/annotations.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/image_file.h"
#include "json_field.h"

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

// An annotated image's size: whole pixels, within the image budget (a COCO RLE mask is decoded at
// this size).
void checkImageSize(const JsonField& entry, int width, int height) {
  if (static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) > kMaxImagePixels) {
    throw Error(entry.file(), entry.field() + " size",
                "an image of at most " + std::to_string(kMaxImagePixels) + " pixels",
                std::to_string(width) + "x" + std::to_string(height));
  }
}

// Coordinates beyond this many pixels are no annotation of a photo (and would wrap an int).
constexpr double kMaxCoordinate = 1e7;

std::array<double, 2> point(const JsonField& x, const JsonField& y) {
  return {x.number(-kMaxCoordinate, kMaxCoordinate), y.number(-kMaxCoordinate, kMaxCoordinate)};
}

AnnotatedImage readLabelMe(const JsonField& j, int* skipped) {
  AnnotatedImage image;
  image.file_name = baseName(j["imagePath"].text());
  image.width = static_cast<int>(j["imageWidth"].integer(1, 1000000));
  image.height = static_cast<int>(j["imageHeight"].integer(1, 1000000));
  checkImageSize(j, image.width, image.height);
  for (const JsonField& s : j["shapes"].elements()) {
    if (!s.isObject()) s.fail("an object (a LabelMe shape)");
    // LabelMe writes "polygon" when shape_type is absent or null.
    const JsonField type_field = s.optional("shape_type");
    const std::string type = type_field.isNull() ? "polygon" : type_field.text();
    AnnotatedShape shape;
    shape.label = s["label"].text();
    std::vector<std::array<double, 2>> ring;
    for (const JsonField& xy : s["points"].elements()) {
      if (xy.size() != 2) xy.fail("[x, y]");
      ring.push_back(point(xy.at(0), xy.at(1)));
    }
    if (type == "rectangle") {
      if (ring.size() != 2) s["points"].fail("2 corners of a rectangle");
      const auto a = ring[0], b = ring[1];
      ring = {a, {b[0], a[1]}, b, {a[0], b[1]}};
    } else if (type == "polygon") {
      if (ring.size() < 3) s["points"].fail("at least 3 points of a polygon");
    } else {
      if (skipped) ++*skipped;  // point, line, linestrip, circle: no area to label
      continue;
    }
    shape.polygons.push_back(std::move(ring));
    image.shapes.push_back(std::move(shape));
  }
  return image;
}

std::vector<AnnotatedImage> readCoco(const JsonField& j) {
  std::map<long long, std::string> categories;
  constexpr long long kMaxId = (1LL << 53);
  for (const JsonField& c : j["categories"].elements()) {
    const long long id = c["id"].integer(-kMaxId, kMaxId);
    if (!categories.emplace(id, c["name"].text()).second) c["id"].fail("an id no other category has");
  }
  std::map<long long, std::size_t> image_index;
  std::vector<AnnotatedImage> images;
  for (const JsonField& im : j["images"].elements()) {
    AnnotatedImage a;
    a.file_name = baseName(im["file_name"].text());
    a.width = static_cast<int>(im["width"].integer(1, 1000000));
    a.height = static_cast<int>(im["height"].integer(1, 1000000));
    checkImageSize(im, a.width, a.height);
    // Two images with one id would draw one photo's annotations on the other.
    if (!image_index.emplace(im["id"].integer(-kMaxId, kMaxId), images.size()).second) {
      im["id"].fail("an id no other image has");
    }
    images.push_back(std::move(a));
  }
  for (const JsonField& an : j["annotations"].elements()) {
    if (!an.isObject()) an.fail("an object (a COCO annotation)");
    const JsonField image_id = an["image_id"], category_id = an["category_id"];
    const auto im = image_index.find(image_id.integer(-kMaxId, kMaxId));
    if (im == image_index.end()) image_id.fail("the id of an entry of images");
    const auto cat = categories.find(category_id.integer(-kMaxId, kMaxId));
    if (cat == categories.end()) category_id.fail("the id of an entry of categories");
    AnnotatedImage& image = images[im->second];
    AnnotatedShape shape;
    shape.label = cat->second;
    const JsonField seg = an["segmentation"];
    if (seg.isArray()) {
      for (const JsonField& poly : seg.elements()) {
        if (poly.size() < 6 || poly.size() % 2 != 0) {
          poly.fail("a polygon [x1, y1, x2, y2, ...] of >= 3 points");
        }
        std::vector<std::array<double, 2>> ring;
        for (std::size_t k = 0; k < poly.size(); k += 2) ring.push_back(point(poly.at(k), poly.at(k + 1)));
        shape.polygons.push_back(std::move(ring));
      }
    } else if (seg.isObject()) {
      const JsonField size = seg["size"];
      if (size.size() != 2) size.fail("[height, width]");
      const long long h = size.at(0).integer(1, 1000000), w = size.at(1).integer(1, 1000000);
      if (h != image.height || w != image.width) {
        size.fail("the image's [" + std::to_string(image.height) + ", " +
                  std::to_string(image.width) + "]");
      }
      std::vector<std::uint32_t> counts;
      const JsonField c = seg["counts"];
      const std::string origin = seg.file() + " (" + seg.field() + ")";
      if (c.isString()) {
        counts = cocoRleCounts(c.text(), origin);
      } else if (c.isArray()) {
        // A run is at most the image's pixel count (a count of 2^32 must not wrap to 0).
        const long long pixels = h * w;
        for (const JsonField& v : c.elements()) counts.push_back(static_cast<std::uint32_t>(v.integer(0, pixels)));
      } else {
        c.fail("a list of runs or a COCO RLE string");
      }
      shape.mask = decodeCocoRle(counts, static_cast<int>(h), static_cast<int>(w), origin);
    } else {
      seg.fail("polygons or an RLE");
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
    if (x < 0 || x > 0xffffffffLL) {
      throw Error(origin, "segmentation.counts", "runs in [0, 2^32)", std::to_string(x));
    }
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
      const json j = readJsonFile(f);
      // Other JSON files in the folder (a classes.json) are not annotations.
      if (!j.is_object() || !j.contains("shapes")) continue;
      images.push_back(readLabelMe(JsonField(j, f), skipped));
    }
    if (images.empty()) {
      throw Error(path, "annotations", "LabelMe .json files (objects with \"shapes\")", "none");
    }
    return images;
  }
  const json j = readJsonFile(path);
  if (j.is_object() && j.contains("shapes")) return {readLabelMe(JsonField(j, path), skipped)};
  if (j.is_object() && j.contains("images") && j.contains("annotations") && j.contains("categories")) {
    return readCoco(JsonField(j, path));
  }
  throw Error(path, "annotations",
              "LabelMe (an object with \"shapes\") or COCO (\"images\", \"annotations\", \"categories\")",
              j.is_object() ? "neither" : j.type_name());
}

}  // namespace io
}  // namespace sadsplat
