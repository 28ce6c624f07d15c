#pragma once
/// \file class_extraction.h
/// \brief Kept for code written against earlier versions: ClassExtraction now lives in the
/// torch-free filters layer (sadsplat/filters/class_extraction.h, target sadsplat::filters).

#include "sadsplat/filters/class_extraction.h"

namespace sadsplat {
namespace semantic_drop {
using filters::ClassExtraction;
}  // namespace semantic_drop
}  // namespace sadsplat
