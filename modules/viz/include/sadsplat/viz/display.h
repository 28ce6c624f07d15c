#pragma once
/// \file display.h
/// \brief Whether VTK can render here. Debian's VTK 9.1 renders through X only (no EGL or
/// OSMesa build): without a display, run under Xvfb (`xvfb-run -a sadsplat view ...`).

#include <string>

namespace sadsplat {
namespace viz {

/// \brief Whether an X display is set (DISPLAY non-empty).
bool haveDisplay();

/// \brief Throws unless an X display is set, saying how to get one.
/// \throws sadsplat::Error naming `what` and the Xvfb remedy
void requireDisplay(const std::string& what);

}  // namespace viz
}  // namespace sadsplat
