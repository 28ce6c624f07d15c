#pragma once
/// \file scene_import.h
/// \brief Importing a scene directory (images/, labels/, sparse/0/, classes.json, split.json).
/// Needs OpenCV (SADSPLAT_WITH_OPENCV); without it importScene throws a clear error.

#include <map>
#include <string>

#include "sadsplat/io/colmap.h"
#include "sadsplat/io/scene.h"
#include "sadsplat/io/transforms_json.h"

namespace sadsplat {
namespace io {

/// \brief How images are resized on import.
struct ImportOptions {
  /// Scale applied to every image (the paper trains at half resolution: 0.5). In (0, 1].
  double scale = 1.0;
  /// If > 0, images wider than this are further scaled down to this width.
  int max_width = 0;
  /// Without split.json: every test_every-th view (sorted by name, from the first) is a test
  /// view and not trained on; 0 trains on every view. Scenes of fewer than 2 * test_every views
  /// train on every view.
  int test_every = 8;
  /// Annotations to rasterise into label maps (io/annotations.h: a LabelMe file or folder, or a
  /// COCO file), matched to views by image file name and to classes.json by class name. Drawn in
  /// the annotated image's pixels, scaled to the scene image's size (same aspect ratio within 2 %),
  /// then undistorted and resized as label maps are. Empty: none.
  std::string annotations;
};

/// \brief The folder of a scene directory's COLMAP model: `dir`/sparse/0 (COLMAP's mapper) or
/// `dir`/sparse (COLMAP's image_undistorter), whichever holds cameras.bin or cameras.txt.
/// \throws sadsplat::Error naming both layouts when neither exists
std::string findColmapModel(const std::string& dir);

/// \brief The posed images of a scene directory, whichever tool wrote them.
struct PosedImages {
  ColmapModel model;      ///< cameras, images (names relative to image_dir), points
  std::string image_dir;  ///< the folder the image names are relative to
  std::string origin;     ///< the COLMAP model folder or the transforms.json (for messages)
  /// image name -> its mask file, from transforms.json's `mask_path` (nerfstudio)
  std::map<std::string, std::string> mask_paths;
};

/// \brief The COLMAP model of `dir` (findColmapModel) with its images in `dir`/images, or, when
/// there is none, `dir`/transforms.json (io/transforms_json.h).
/// \throws sadsplat::Error naming the layouts when there is neither
PosedImages readPosedImages(const std::string& dir, const ImageSizeOf& image_size);

/// \brief The split of a scene without split.json (ImportOptions::test_every).
SplitInfo defaultSplit(const ColmapModel& model, int test_every);

/// \brief Whether this build can import scene directories (it has OpenCV).
bool haveSceneImport();

/// \brief Imports a scene directory.
///
/// Images are decoded, undistorted to a pinhole camera (SIMPLE_RADIAL, RADIAL, OPENCV), and
/// resized; label maps (labels/<image stem>.png: 8-bit class ids with 255 = ignore, or colour
/// PNGs mapped through the class colours with black = ignore unless a class is black) are
/// warped the same way with nearest-neighbour sampling. classes.json is optional: without it the
/// scene has no classes (plain 3DGS) and may have no label maps. split.json is optional: without
/// it ImportOptions::test_every decides the test views and every training view with a label map
/// is labelled. Masks keep pixels out of training (moving cars, people, the drone's legs): a
/// frame's `mask_path` in transforms.json, else masks/<image name>.png or masks/<image stem>.png
/// (COLMAP's and OpenDroneMap's layouts); 8-bit, the image's size, 0 = leave out, anything else
/// = keep. Left-out pixels join the view's mask (outside the undistorted image) and lose their
/// labels.
/// \throws sadsplat::Error naming the file, the field and the expectation
Scene importScene(const std::string& dir, const ImportOptions& options = {});

}  // namespace io
}  // namespace sadsplat
