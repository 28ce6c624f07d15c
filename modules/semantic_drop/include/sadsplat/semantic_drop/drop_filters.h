#pragma once
/// \file drop_filters.h
/// \brief Kept for code written against earlier versions: the drop filters now live in the
/// torch-free filters layer (sadsplat/filters/drop_filters.h, target sadsplat::filters).

#include "sadsplat/filters/drop_filters.h"

namespace sadsplat {
namespace semantic_drop {
using filters::ConfidenceDrop;
using filters::DropFilter;
using filters::HardConcreteDrop;
using filters::SemanticDrop;
}  // namespace semantic_drop
}  // namespace sadsplat
