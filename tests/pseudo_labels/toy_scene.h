#pragma once
// A toy scene for the pseudo-label tests: 3 classes ("red", "green", "blue" prompts), views whose
// pixels are blocks of the class colours with seeded noise, label maps on every view, view 0
// labelled, views 0..n-2 training, the last one test. No geometry (no sparse points).

#include <random>

#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace test {

inline io::Scene toyPseudoLabelScene(int views = 5, int W = 64, int H = 48,
                                     std::uint64_t seed = 1) {
  io::Scene scene;
  scene.source = "<toy scene>";
  const char* names[3] = {"red", "green", "blue"};
  const std::uint8_t colours[3][3] = {{200, 40, 40}, {40, 180, 60}, {50, 60, 200}};
  for (int c = 0; c < 3; ++c) {
    ClassInfo info;
    info.name = names[c];
    info.prompt = names[c];
    info.color = {colours[c][0], colours[c][1], colours[c][2]};
    scene.classes.push_back(info);
  }
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 8.0);
  for (int v = 0; v < views; ++v) {
    io::View view;
    view.name = "view_" + std::to_string(v) + ".png";
    view.camera.width = W;
    view.camera.height = H;
    view.camera.fx = view.camera.fy = W;
    view.camera.cx = W / 2.0;
    view.camera.cy = H / 2.0;
    view.camera.tvec = {0, 0, 10};
    view.rgb = {W, H, 3, std::vector<std::uint8_t>(static_cast<std::size_t>(W) * H * 3)};
    view.mask = {W, H, 1, std::vector<std::uint8_t>(static_cast<std::size_t>(W) * H, 255)};
    view.labels = {W, H, 1, std::vector<std::uint8_t>(static_cast<std::size_t>(W) * H)};
    for (int y = 0; y < H; ++y) {
      for (int x = 0; x < W; ++x) {
        // 16x16 blocks whose class shifts with the view.
        const int c = ((x / 16) + 2 * (y / 16) + v) % 3;
        const std::size_t i = static_cast<std::size_t>(y) * W + x;
        view.labels.pixels[i] = static_cast<std::uint8_t>(c);
        for (int k = 0; k < 3; ++k) {
          view.rgb.pixels[3 * i + k] =
              static_cast<std::uint8_t>(std::clamp(colours[c][k] + noise(rng), 0.0, 255.0));
        }
      }
    }
    view.train = v < views - 1;
    view.test = !view.train;
    view.labelled = v == 0;
    scene.views.push_back(view);
  }
  return scene;
}

}  // namespace test
}  // namespace sadsplat
