#pragma once
/// \file tensor_archive.h
/// \brief A small, versioned binary file of named tensors and numbers (training checkpoints).
///
/// Layout (little endian): magic "SADSCKPT", u32 version (1), u64 entry count, then per entry:
/// u32 name length + name, u8 kind (0 tensor, 1 double), and for a tensor u8 dtype (0 float32,
/// 1 int32, 2 int64), u32 ndim, i64 sizes[ndim], raw data; for a double the 8 bytes. Written
/// atomically; a truncated or foreign file is a sadsplat::Error.

#include <ATen/ATen.h>

#include <map>
#include <string>

namespace sadsplat {
namespace gaussians {

/// \brief Named CPU tensors and scalars.
struct TensorArchive {
  std::map<std::string, at::Tensor> tensors;
  std::map<std::string, double> numbers;

  /// \brief The tensor called `name`.
  /// \throws sadsplat::Error naming `file` if it is missing
  const at::Tensor& tensor(const std::string& name, const std::string& file) const;
  /// \brief The number called `name`.
  double number(const std::string& name, const std::string& file) const;
};

/// \brief Writes an archive (tensors are copied to the CPU).
void writeTensorArchive(const std::string& path, const TensorArchive& archive);
/// \brief Reads an archive written by writeTensorArchive.
TensorArchive readTensorArchive(const std::string& path);

}  // namespace gaussians
}  // namespace sadsplat
