#pragma once
/// \file scene.h
/// \brief An imported scene in memory: classes, posed pinhole views with images, label maps and
/// masks, and the sparse points. Plain data, no OpenCV: the GPU build reads it from the cache.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "sadsplat/common/class_info.h"
#include "sadsplat/io/georeference.h"

namespace sadsplat {
namespace io {

/// \brief Label value of a pixel with no class (sky, outside the undistorted image, unlabelled).
constexpr std::uint8_t kIgnoreLabel = 255;

/// \brief An undistorted pinhole camera with its pose, in COLMAP conventions:
/// x_cam = R(qvec) x_world + tvec, qvec = (w, x, y, z), pixel centres at +0.5.
struct PinholeCamera {
  int width = 0;
  int height = 0;
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::array<double, 4> qvec{1, 0, 0, 0};
  std::array<double, 3> tvec{0, 0, 0};

  /// \brief R(qvec), row-major (qvec is normalised first, so any non-zero quaternion works).
  std::array<double, 9> rotation() const;

  /// \brief Throws unless this is a camera sadsplat can train on and read back from a scene
  /// cache: a size of 1..kMaxImagePixels pixels, finite focal lengths of at least 0.001 px, a
  /// finite principal point and translation, a finite non-zero quaternion.
  /// \param[in] origin the file the camera came from; \param[in] field where in it ("view a.jpg")
  void validate(const std::string& origin, const std::string& field) const;
};

/// \brief A camera's projection of world points into its image, R(qvec) computed once.
class PointProjector {
 public:
  explicit PointProjector(const PinholeCamera& camera) : camera_(camera), R_(camera.rotation()) {}
  /// \brief The pixel (u, v) and camera depth z of world point `x`; false when it lies behind the
  /// camera (z not above 1e-6, or not a number) or outside the image ([0, width) x [0, height)).
  bool project(const std::array<float, 3>& x, double* u, double* v, double* z) const;

 private:
  const PinholeCamera& camera_;
  std::array<double, 9> R_;
};

/// \brief An 8-bit image, row-major, channels interleaved.
struct Image8 {
  int width = 0;
  int height = 0;
  int channels = 0;
  std::vector<std::uint8_t> pixels;  ///< width * height * channels bytes

  bool empty() const { return pixels.empty(); }
  std::uint8_t at(int x, int y, int c = 0) const {
    return pixels[(static_cast<std::size_t>(y) * width + x) * channels + c];
  }
};

/// \brief Pseudo-labels of one view (paper, "Pseudo-Label Generation Module"), stored compactly:
/// the view is split into targets (regions); each target carries its class scores, its feature
/// and whether the TOP1 / dTOP / entropy filter kept it. The confidence map (H x W x C) is the
/// target's scores at the target's pixels and 0 outside any target; the pseudo-label map is the
/// argmax of a kept target's scores; the pseudo-feature map is a kept target's feature.
struct ViewPseudoLabels {
  std::string backend;               ///< "builtin" or "torchscript" (informational)
  std::vector<std::int32_t> region;  ///< per pixel (row-major): target id, or -1 for none
  int num_targets = 0;
  int num_classes = 0;
  std::vector<float> scores;  ///< num_targets x num_classes, each row a distribution
  int feature_dim = 0;
  std::vector<float> features;     ///< num_targets x feature_dim
  std::vector<std::uint8_t> kept;  ///< num_targets: 1 = passed the filter

  bool empty() const { return region.empty(); }
  /// \brief Per target, kept or not: the class of its highest score (the first one on ties).
  std::vector<std::int16_t> targetClasses() const;
  /// \brief Class of the kept target at each pixel, or -1 (not kept, no target).
  std::vector<std::int16_t> labelMap() const;
  /// \brief The confidence map's maximum over classes at each pixel (0 outside any target).
  std::vector<float> maxScoreMap() const;
  /// \brief The dense confidence map, H x W x C floats (pixel-major).
  std::vector<float> confidenceMap() const;
  /// \brief Checks sizes and ranges against a view of `pixels` pixels.
  /// \throws sadsplat::Error naming `origin` and the field
  void validate(const std::string& origin, std::size_t pixels) const;
};

/// \brief Where the pixels of a view wait in a scene cache read by readSceneCacheWithoutPixels
/// (scene_cache.h): the file and the byte ranges of the view's chunks; readViewPixels reads them.
struct ViewPixelsInCache {
  std::string path;
  std::uint32_t version = 0;
  std::size_t classes = 0;        ///< the scene's class count (label ids are checked against it)
  std::uint64_t view_offset = 0;  ///< the VIEW chunk's content: offset in the file, size
  std::uint64_t view_size = 0;
  std::uint64_t pseudo_offset = 0;  ///< the PSLB chunk's content (size 0: no pseudo-labels)
  std::uint64_t pseudo_size = 0;
  bool has_labels = false;
};

/// \brief One posed image of the scene.
struct View {
  std::string name;         ///< image file name, relative to images/
  PinholeCamera camera;     ///< already undistorted and resized to the image below
  Image8 rgb;               ///< 3 channels
  Image8 mask;              ///< 1 channel: 255 = valid pixel, 0 = outside the undistorted image
  Image8 labels;            ///< 1 channel class ids (kIgnoreLabel = none); empty if unlabelled
  bool train = false;       ///< in the training set
  bool test = false;        ///< in the test set
  bool labelled = false;    ///< a training view whose label map supervises training
  ViewPseudoLabels pseudo;  ///< empty until `sadsplat pseudo-labels` ran on the scene
  /// Set when the scene was read without pixels: rgb, mask, labels and pseudo are then empty and
  /// wait in the cache (io::readViewPixels).
  std::shared_ptr<const ViewPixelsInCache> pixels_in_cache;

  /// \brief Whether the view has a label map, held or waiting in a cache.
  bool hasLabels() const {
    return !labels.empty() || (pixels_in_cache && pixels_in_cache->has_labels);
  }
  /// \brief Whether the view has pseudo-labels, held or waiting in a cache.
  bool hasPseudoLabels() const {
    return !pseudo.empty() || (pixels_in_cache && pixels_in_cache->pseudo_size > 0);
  }
};

/// \brief The class ids that supervise the semantic loss on a view, -1 = none: on a labelled view
/// its ground truth (ground truth always wins over pseudo-labels, also where it says "ignore"),
/// otherwise the kept pseudo-labels if `use_pseudo` and the view has them, otherwise all -1.
/// Pixels outside the view's mask are -1.
std::vector<std::int16_t> supervisionLabels(const View& view, bool use_pseudo = true);

/// \brief One sparse (SfM) point.
struct ScenePoint {
  std::array<float, 3> xyz{0, 0, 0};
  std::array<std::uint8_t, 3> rgb{0, 0, 0};
};

/// \brief A whole scene.
struct Scene {
  std::string source;  ///< where it was imported from (informational)
  std::vector<ClassInfo> classes;
  std::vector<View> views;  ///< sorted by name
  std::vector<ScenePoint> points;
  /// Where the scene is on the Earth (its frame is then east-north-up metres); none for scenes
  /// without GPS (an arbitrary SfM frame).
  std::optional<Georeference> georeference;
};

/// \brief Per class of `scene`, how many pixels of its labelled training views (their label maps
/// held in memory) carry that class: a class at 0 is one no annotated photo shows, which neither
/// the annotations nor the pseudo-labels (a classifier of the annotated classes) can teach.
/// `*views` (optional) gets how many labelled training views were counted.
std::vector<std::int64_t> annotatedPixelsPerClass(const Scene& scene, int* views = nullptr);

/// \brief The class list and split of a scene directory, readable without OpenCV.
struct SplitInfo {
  std::vector<std::string> train;     ///< image names
  std::vector<std::string> test;      ///< image names
  std::vector<std::string> labelled;  ///< subset of train whose label maps supervise training
};

/// \brief Reads classes.json: {"classes": [{"name": s, "color": [r, g, b], "prompt": s}, ...]}.
/// `prompt` is optional (defaults to the name). Names must be unique; at most 255 classes.
/// \throws sadsplat::Error naming the file and the field
std::vector<ClassInfo> readClassesJson(const std::string& path);

/// \brief Reads split.json: {"train": [names], "test": [names], "labelled": [names]}.
/// \throws sadsplat::Error naming the file and the field
SplitInfo readSplitJson(const std::string& path);

/// \brief Writes classes.json (atomically) in the format readClassesJson reads.
void writeClassesJson(const std::string& path, const std::vector<ClassInfo>& classes);
/// \brief Writes split.json (atomically) in the format readSplitJson reads.
void writeSplitJson(const std::string& path, const SplitInfo& split);

}  // namespace io
}  // namespace sadsplat
