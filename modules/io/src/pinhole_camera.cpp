#include <cmath>

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

}  // namespace io
}  // namespace sadsplat
