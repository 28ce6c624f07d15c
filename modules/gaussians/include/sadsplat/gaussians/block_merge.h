#pragma once
/// \file block_merge.h
/// \brief One model from models trained block by block (geo/block_partition.h): each block's
/// Gaussians inside its own cell, concatenated, and the blocks' semantic decoders made one.

#include <ATen/ATen.h>

#include <string>
#include <vector>

#include "sadsplat/gaussians/tensor_archive.h"

namespace sadsplat {
namespace gaussians {

/// \brief A block's training state and the Gaussians the merge keeps from it.
struct BlockCheckpoint {
  TensorArchive archive;  ///< the block run's checkpoint (Trainer::checkpointSnapshot)
  at::Tensor keep;        ///< [N] bool: its Gaussians whose centre lies in the block's cell
  std::string origin;     ///< the checkpoint's file, for errors
};

/// \brief Concatenates the kept rows of every per-Gaussian tensor (`row_tensors`, from
/// Trainer::checkpointRowTensors) in block order; the global tensors and numbers (the decoder,
/// the drop's guard, the iteration) are the `reference` block's.
///
/// The decoders are made one: the model keeps block `reference`'s decoder (W0, b0), and every
/// other block's features f become the features W0, b0 decode to what the block's own decoder
/// made of them: f' = pinv(W0) (W f + b - b0) (least squares; exact when W0 has full row rank,
/// i.e. feature_dim >= classes as with the defaults), so every Gaussian keeps its class scores
/// and its label. A rendered feature image then decodes as before where the pixel is opaque; the
/// biases differ by (b - b0)(1 - sum of the blending weights) elsewhere. The moved features'
/// Adam moments restart at zero.
/// \throws sadsplat::Error naming the block's origin when the blocks disagree in tensors or shapes
TensorArchive mergeBlockCheckpoints(const std::vector<BlockCheckpoint>& blocks,
                                    const std::vector<std::string>& row_tensors, int reference);

}  // namespace gaussians
}  // namespace sadsplat
