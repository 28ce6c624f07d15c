#pragma once
/// \file scene_writer.h
/// \brief Writing a generated scene as a scene directory and a contact sheet (needs OpenCV).

#include <string>

#include "sadsplat/synth/aerial_benchmark.h"

namespace sadsplat {
namespace synth {

/// \brief How writeScene stores the COLMAP model in sparse/0.
enum class ColmapFormat {
  kText,    ///< cameras.txt, images.txt, points3D.txt
  kBinary,  ///< cameras.bin, images.bin, points3D.bin (what tools reading binary models only need)
};

/// \brief Writes the scene directory (creating it), atomically file by file: images/, labels/
/// (every view), depth/*.npy (float32 camera z, 0 = sky), sparse/0 (COLMAP, text by default),
/// classes.json, split.json.
void writeScene(const SynthScene& scene, const std::string& dir,
                ColmapFormat colmap = ColmapFormat::kText);

/// \brief Writes a contact sheet: a few views beside their label maps (class colours).
void writeContactSheet(const SynthScene& scene, const std::string& png_path);

}  // namespace synth
}  // namespace sadsplat
