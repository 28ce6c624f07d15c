#pragma once
/// \file annotations.h
/// \brief Annotations from labelling tools: LabelMe JSON (one file per image, polygons and
/// rectangles) and COCO JSON (polygons and RLE masks, as CVAT and Label Studio export). Read into
/// shapes per image file name; sadsplat's import rasterises them into label maps
/// (io::ImportOptions::annotations). No OpenCV here.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace sadsplat {
namespace io {

/// \brief One labelled region: polygons (closed rings, pixel coordinates of the annotated image,
/// x right, y down, pixel centres at +0.5) or a run-length mask, of one class name.
struct AnnotatedShape {
  std::string label;
  std::vector<std::vector<std::array<double, 2>>> polygons;  ///< empty when `mask` is used
  std::vector<std::uint8_t> mask;  ///< row-major, width x height of the image; empty for polygons
};

/// \brief The shapes of one annotated image, in drawing order (later shapes paint over earlier).
struct AnnotatedImage {
  std::string file_name;  ///< the image's file name without folders ("DJI_0018.JPG")
  int width = 0;          ///< the annotated image's size
  int height = 0;
  std::vector<AnnotatedShape> shapes;
};

/// \brief Reads annotations: a COCO JSON file (an object with "images", "annotations" and
/// "categories"), a LabelMe JSON file (an object with "shapes"), or a folder of LabelMe files
/// (its other .json files are skipped).
/// Shapes LabelMe draws as "polygon" and "rectangle" are read; "point", "line", "linestrip" and
/// "circle" are skipped (they cover no area) and counted in `skipped`.
/// \throws sadsplat::Error naming the file and the field (a polygon with fewer than 3 points, an
/// RLE whose counts do not add up to its size, a category id no category has, ...)
std::vector<AnnotatedImage> readAnnotations(const std::string& path, int* skipped = nullptr);

/// \brief Decodes a COCO RLE mask: `counts` (alternating runs of 0 and 1, column-major, starting
/// with 0) for an image of `height` x `width`; the result is row-major. `compressed` is COCO's
/// string form (pycocotools' LEB128-like characters from 48).
/// \throws sadsplat::Error naming `origin` when the runs do not cover the image exactly
std::vector<std::uint8_t> decodeCocoRle(const std::vector<std::uint32_t>& counts, int height,
                                        int width, const std::string& origin);
/// \brief COCO's compressed RLE string into its run counts.
std::vector<std::uint32_t> cocoRleCounts(const std::string& compressed, const std::string& origin);

}  // namespace io
}  // namespace sadsplat
