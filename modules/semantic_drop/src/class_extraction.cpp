#include "sadsplat/semantic_drop/class_extraction.h"

#include <pcl/point_types.h>

#include "sadsplat/semantic_drop/impl/class_extraction.hpp"

template class sadsplat::semantic_drop::ClassExtraction<sadsplat::GaussianPoint>;
template class sadsplat::semantic_drop::ClassExtraction<pcl::PointXYZRGBL>;
