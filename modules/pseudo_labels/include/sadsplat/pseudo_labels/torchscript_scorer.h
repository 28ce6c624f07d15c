#pragma once
/// \file torchscript_scorer.h
/// \brief The foundation-model backend: SAM's automatic masks as targets and a CLIP-family model
/// (GeoRSCLIP is an open_clip ViT) as the region and text embedder, both loaded from TorchScript
/// files written by scripts/export_foundation_models.py.
///
/// The contract of the two files (the export script implements it; tests use tiny random models
/// of the same interface from scripts/make_tiny_foundation_models.py):
/// - SAM: `encode(image[1, 3, H, W] float RGB 0..255) -> embedding` and
///   `decode(embedding, points[B, 2] float pixel (x, y), H: int, W: int) -> (mask logits
///   [B, K, H, W], predicted IoU [B, K])`; the module does its own resizing and normalisation.
/// - CLIP: `encode_image(images[B, 3, S, S] float RGB 0..1) -> [B, E]`, an int attribute
///   `image_size` (S), a float attribute `logit_scale`, a tensor attribute `text_embeddings`
///   [C, E] and a list attribute `class_prompts` (C strings) — the text side is encoded at export
///   time for the scene's prompts, so no tokenizer is needed in C++; the prompts must equal the
///   scene's (classes.json "prompt") or the run stops with an error naming both lists.
///
/// Automatic mask generation follows SAM's recipe: a regular grid of point prompts, masks kept if
/// their predicted IoU and their stability score (IoU of the mask thresholded at +offset and
/// -offset) pass thresholds, non-maximum suppression on box IoU, then masks are painted from
/// the largest to the smallest so that every pixel belongs to at most one target.

#include <string>

#include "sadsplat/pseudo_labels/generator.h"

namespace sadsplat {
namespace pseudo_labels {

/// \brief Automatic mask generation parameters (SAM's defaults where they exist).
struct MaskGenerationOptions {
  int points_per_side = 32;
  int points_per_batch = 64;
  double pred_iou_threshold = 0.88;
  double stability_threshold = 0.95;
  double stability_offset = 1.0;
  double box_nms_threshold = 0.7;
  int min_mask_pixels = 16;
  std::string device = "cpu";  ///< "cpu" or "cuda"
};

/// \brief Loads the two TorchScript files (checked at once: a missing file, a file that is not
/// TorchScript, or a module without the methods and attributes above gives an Error naming the
/// file and what is missing).
TargetScorer::Ptr makeTorchScriptScorer(const std::string& sam_path, const std::string& clip_path,
                                        const MaskGenerationOptions& options = {});

/// \brief Box non-maximum suppression: indices of the boxes kept, by descending score.
/// \param[in] boxes x0, y0, x1, y1 per box (inclusive pixel bounds)
std::vector<int> boxNms(const std::vector<std::array<float, 4>>& boxes,
                        const std::vector<float>& scores, double iou_threshold);

}  // namespace pseudo_labels
}  // namespace sadsplat
