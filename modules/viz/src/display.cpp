#include "sadsplat/viz/display.h"

#include <cstdlib>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace viz {

bool haveDisplay() {
  const char* display = std::getenv("DISPLAY");
  return display != nullptr && display[0] != '\0';
}

void requireDisplay(const std::string& what) {
  if (!haveDisplay()) {
    // VTK's X render window aborts the process without a display: say so before it tries.
    throw Error(what, "DISPLAY", "an X display (VTK renders through X)",
                "none: run under `xvfb-run -a` (Debian package xvfb) on a machine without one");
  }
}

}  // namespace viz
}  // namespace sadsplat
