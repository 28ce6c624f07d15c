#pragma once
/// \file device.h
/// \brief The device a configuration names ("cpu" or "cuda"), as LibTorch's at::Device.

#include <ATen/ATen.h>

#include <string>

namespace sadsplat {
namespace gaussians {

/// \brief "cpu" → the CPU, "cuda" → the first CUDA device (whether one exists is the caller's
/// check: the trainer says so with the configuration's name).
/// \throws sadsplat::Error naming `origin` for any other name
at::Device deviceNamed(const std::string& name, const std::string& origin = "<device>");

}  // namespace gaussians
}  // namespace sadsplat
