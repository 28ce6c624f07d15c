#pragma once
/// \file demo.h
/// \brief `sadsplat demo`: the method end to end on a small generated city, on the CPU.

#include <ostream>
#include <string>

namespace sadsplat {
namespace pipeline {

/// \brief Generates the small city scene, writes its pseudo-labels (built-in backend, report in
/// OUT/pseudo_labels), trains on CPU with the full semantic-aware drop, evaluates, prints a table
/// to `out`. `baseline` skips pseudo-labels and drop (the paper's Net-1). Returns 0 on success.
int runDemo(const std::string& out_dir, int iterations, std::ostream& out, bool baseline = false);

}  // namespace pipeline
}  // namespace sadsplat
