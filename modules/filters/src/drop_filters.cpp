#include "sadsplat/filters/drop_filters.h"

#include "sadsplat/filters/impl/drop_filters.hpp"

template class sadsplat::filters::DropFilter<sadsplat::GaussianPoint>;
template class sadsplat::filters::HardConcreteDrop<sadsplat::GaussianPoint>;
template class sadsplat::filters::ConfidenceDrop<sadsplat::GaussianPoint>;
template class sadsplat::filters::SemanticDrop<sadsplat::GaussianPoint>;
