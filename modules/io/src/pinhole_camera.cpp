#include <cmath>
#include <cstdint>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/io/image_file.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace io {

std::array<double, 9> PinholeCamera::rotation() const {
  const double n =
      std::sqrt(qvec[0] * qvec[0] + qvec[1] * qvec[1] + qvec[2] * qvec[2] + qvec[3] * qvec[3]);
  const double w = qvec[0] / n, x = qvec[1] / n, y = qvec[2] / n, z = qvec[3] / n;
  return {1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
}

bool PointProjector::project(const std::array<float, 3>& x, double* u, double* v, double* z) const {
  const auto& R = R_;
  const auto& t = camera_.tvec;
  const double xc = R[0] * x[0] + R[1] * x[1] + R[2] * x[2] + t[0];
  const double yc = R[3] * x[0] + R[4] * x[1] + R[5] * x[2] + t[1];
  *z = R[6] * x[0] + R[7] * x[1] + R[8] * x[2] + t[2];
  if (!(*z > 1e-6)) return false;
  *u = camera_.fx * xc / *z + camera_.cx;
  *v = camera_.fy * yc / *z + camera_.cy;
  return *u >= 0 && *v >= 0 && *u < camera_.width && *v < camera_.height;
}

void PinholeCamera::validate(const std::string& origin, const std::string& field) const {
  if (width <= 0 || height <= 0 ||
      static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) > kMaxImagePixels) {
    throw Error(origin, field + " size",
                "a positive size of at most " + std::to_string(kMaxImagePixels) + " pixels",
                std::to_string(width) + "x" + std::to_string(height));
  }
  // Focal lengths below a thousandth of a pixel (or infinite) are no cameras: they would train on
  // NaN rays without a word.
  if (!(fx >= 1e-3 && fy >= 1e-3 && std::isfinite(fx) && std::isfinite(fy))) {
    std::ostringstream got;
    got << fx << " / " << fy;
    throw Error(origin, field + " fx / fy", "finite focal lengths of at least 0.001 px", got.str());
  }
  if (!std::isfinite(cx) || !std::isfinite(cy)) {
    throw Error(origin, field + " cx / cy", "a finite principal point", "not finite");
  }
  double qnorm2 = 0;
  for (double q : qvec) qnorm2 += q * q;
  if (!(qnorm2 > 1e-12 && std::isfinite(qnorm2))) {
    throw Error(origin, field + " qvec", "a non-zero rotation quaternion (finite)",
                "zero or not finite");
  }
  for (double t : tvec) {
    if (!std::isfinite(t))
      throw Error(origin, field + " tvec", "a finite translation", "not finite");
  }
}

}  // namespace io
}  // namespace sadsplat
