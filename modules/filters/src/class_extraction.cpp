#include "sadsplat/filters/class_extraction.h"

#include <pcl/point_types.h>

#include "sadsplat/filters/impl/class_extraction.hpp"

template class sadsplat::filters::ClassExtraction<sadsplat::GaussianPoint>;
template class sadsplat::filters::ClassExtraction<pcl::PointXYZRGBL>;
