#include "sadsplat/gaussians/block_merge.h"

#include <algorithm>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace gaussians {
namespace {

std::string shapeText(const at::Tensor& t) {
  std::string s = "[";
  for (std::int64_t i = 0; i < t.dim(); ++i) s += (i ? ", " : "") + std::to_string(t.size(i));
  return s + "]";
}

// Block k's features expressed for the reference decoder (see the header).
at::Tensor featuresForDecoder(const TensorArchive& block, const TensorArchive& reference,
                              const at::Tensor& pinv_w0, const std::string& origin) {
  const at::Tensor f = block.tensor("features", origin).to(at::kDouble);
  const at::Tensor w = block.tensor("decoder_w", origin).to(at::kDouble);
  const at::Tensor b = block.tensor("decoder_b", origin).to(at::kDouble);
  const at::Tensor b0 = reference.tensor("decoder_b", origin).to(at::kDouble);
  const at::Tensor scores = at::linear(f, w, b);                 // [N, C]
  return at::linear(scores - b0, pinv_w0).to(at::kFloat);        // [N, D]
}

}  // namespace

TensorArchive mergeBlockCheckpoints(const std::vector<BlockCheckpoint>& blocks,
                                    const std::vector<std::string>& row_tensors, int reference) {
  if (blocks.empty()) throw Error("<block merge>", "blocks", "at least one block", "none");
  if (reference < 0 || reference >= static_cast<int>(blocks.size()))
    throw Error("<block merge>", "reference", "a block index", std::to_string(reference));
  const TensorArchive& ref = blocks[reference].archive;
  TensorArchive merged;
  merged.numbers = ref.numbers;
  const auto is_row = [&](const std::string& name) {
    return std::find(row_tensors.begin(), row_tensors.end(), name) != row_tensors.end();
  };
  for (const auto& [name, tensor] : ref.tensors) {
    if (!is_row(name)) merged.tensors[name] = tensor;
  }
  for (const BlockCheckpoint& b : blocks) {
    if (b.archive.tensors.size() != ref.tensors.size())
      throw Error(b.origin, "tensors",
                  std::to_string(ref.tensors.size()) + " as in " + blocks[reference].origin,
                  std::to_string(b.archive.tensors.size()));
    for (const auto& [name, tensor] : ref.tensors) {
      const at::Tensor& t = b.archive.tensor(name, b.origin);
      if (!is_row(name) && !t.sizes().equals(tensor.sizes()))
        throw Error(b.origin, "tensor " + name, shapeText(tensor), shapeText(t));
    }
  }
  const bool semantic = ref.tensors.count("decoder_w") && ref.tensors.at("decoder_w").numel() > 0;
  at::Tensor pinv_w0;
  if (semantic) pinv_w0 = at::linalg_pinv(ref.tensors.at("decoder_w").to(at::kDouble));
  for (const std::string& name : row_tensors) {
    std::vector<at::Tensor> parts;
    for (std::size_t k = 0; k < blocks.size(); ++k) {
      const BlockCheckpoint& b = blocks[k];
      const at::Tensor keep = b.keep.to(at::kCPU).to(at::kBool);
      const at::Tensor& t = b.archive.tensor(name, b.origin);
      if (t.size(0) != keep.size(0))
        throw Error(b.origin, "tensor " + name, std::to_string(keep.size(0)) + " rows",
                    std::to_string(t.size(0)));
      at::Tensor rows = t.index({keep});
      const bool moved = semantic && static_cast<int>(k) != reference;
      if (moved && name == "features") {
        rows = featuresForDecoder(b.archive, ref, pinv_w0, b.origin).index({keep});
      } else if (moved && (name == "features.m" || name == "features.v")) {
        rows = at::zeros_like(rows);
      }
      parts.push_back(rows);
    }
    merged.tensors[name] = at::cat(parts, 0);
  }
  return merged;
}

}  // namespace gaussians
}  // namespace sadsplat
