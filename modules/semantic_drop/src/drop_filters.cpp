#include "sadsplat/semantic_drop/drop_filters.h"

#include "sadsplat/semantic_drop/impl/drop_filters.hpp"

template class sadsplat::semantic_drop::DropFilter<sadsplat::GaussianPoint>;
template class sadsplat::semantic_drop::HardConcreteDrop<sadsplat::GaussianPoint>;
template class sadsplat::semantic_drop::ConfidenceDrop<sadsplat::GaussianPoint>;
template class sadsplat::semantic_drop::SemanticDrop<sadsplat::GaussianPoint>;
