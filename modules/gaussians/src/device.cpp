#include "sadsplat/gaussians/device.h"

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace gaussians {

at::Device deviceNamed(const std::string& name, const std::string& origin) {
  if (name == "cpu") return at::Device(at::kCPU);
  if (name == "cuda") return at::Device(at::kCUDA, 0);
  throw Error(origin, "device", "cpu or cuda", name);
}

}  // namespace gaussians
}  // namespace sadsplat
