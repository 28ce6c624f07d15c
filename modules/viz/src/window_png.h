#pragma once
// A rendered VTK window as a PNG file, written atomically.
#include <vtkRenderWindow.h>

#include <string>

namespace sadsplat {
namespace viz {

// Renders `window` and writes its colour buffer (RGB) to `path` (temporary file + rename).
void saveWindowPng(vtkRenderWindow* window, const std::string& path);

}  // namespace viz
}  // namespace sadsplat
