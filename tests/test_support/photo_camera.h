#pragma once
// A small photo camera shared by the gaussians suites that compare a Gaussian's depth with the
// surface a camera renders (contribution, surface layer).

#include "sadsplat/gaussians/rasterizer.h"

namespace sadsplat {
namespace test {

/// 64 x 48 pixels, focal length 60, centred principal point, at (centre_x, 0, 0) looking along +z.
inline gaussians::RasterCamera smallPhotoCamera(double centre_x = 0) {
  gaussians::RasterCamera c;
  c.width = 64;
  c.height = 48;
  c.fx = c.fy = 60;
  c.cx = 32;
  c.cy = 24;
  c.tvec = {-centre_x, 0, 0};
  return c;
}

}  // namespace test
}  // namespace sadsplat
