// Semantic loss benchmark (a program, not a test): forward and forward+backward time of the fused
// semantic loss against the reference composition, on the rasterizer's layout (the D feature
// channels are a slice of a [H, W, 3 + D] image), same inputs, same run.
//   sadsplat_bench_semantic_loss [--device cuda|cpu] [--width 800] [--height 450] [--features 32]
//                                [--classes 6] [--supervised 0.7] [--repeats 50]
#include <CLI/CLI.hpp>

#include <ATen/Context.h>
#include <torch/csrc/autograd/autograd.h>

#include <chrono>
#include <cstdio>
#include <string>

#include "bench_support.h"
#include "sadsplat/gaussians/semantic_loss.h"
#include "sadsplat/gaussians/device.h"

int main(int argc, char** argv) {
  CLI::App app{"Semantic loss: fused vs reference, forward and forward+backward"};
  std::string device_name = "cuda";
  int width = 800, height = 450, features = 32, classes = 6, repeats = 50;
  double supervised = 0.7;
  app.add_option("--device", device_name, "cpu or cuda")->capture_default_str();
  app.add_option("--width", width)->capture_default_str();
  app.add_option("--height", height)->capture_default_str();
  app.add_option("--features", features)->capture_default_str();
  app.add_option("--classes", classes)->capture_default_str();
  app.add_option("--supervised", supervised, "share of labelled pixels")->capture_default_str();
  app.add_option("--repeats", repeats)->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (device_name == "cuda" && !at::hasCUDA()) {
    std::fprintf(stderr, "no CUDA device\n");
    return 1;
  }
  const at::Device device = sadsplat::gaussians::deviceNamed(device_name, "--device");
  at::manual_seed(0);
  const auto opts = at::TensorOptions().dtype(at::kFloat).device(device);
  const at::Tensor image_data = at::randn({height, width, 3 + features}, opts);
  at::Tensor labels = at::randint(0, classes, {height, width}, opts.dtype(at::kLong));
  labels =
      at::where(at::rand({height, width}, opts) < supervised, labels, at::full_like(labels, -1));
  const at::Tensor weight_data = at::randn({classes, features}, opts) * 0.3;
  const at::Tensor bias_data = at::randn({classes}, opts) * 0.1;
  std::printf("| variant | fused | forward ms | forward+backward ms |\n|---|---|---|---|\n");
  using Clock = std::chrono::steady_clock;
  for (const bool fused : {false, true}) {
    double fwd_ms = 0, both_ms = 0;
    bool took_fused = false;
    for (int r = -3; r < repeats; ++r) {
      const at::Tensor image = image_data.clone().requires_grad_(true);
      const at::Tensor w = weight_data.clone().requires_grad_(true);
      const at::Tensor b = bias_data.clone().requires_grad_(true);
      const at::Tensor f = image.slice(2, 3, 3 + features);
      took_fused = fused && sadsplat::gaussians::semanticLossIsFused(f, labels, w, b);
      sadsplat::bench::synchronize(device);
      const auto t0 = Clock::now();
      const at::Tensor value = fused ? sadsplat::gaussians::semanticLoss(f, labels, w, b)
                                     : sadsplat::gaussians::semanticLossReference(f, labels, w, b);
      sadsplat::bench::synchronize(device);
      const auto t1 = Clock::now();
      torch::autograd::grad({value}, {image, w, b});
      sadsplat::bench::synchronize(device);
      const auto t2 = Clock::now();
      if (r >= 0) {
        fwd_ms += std::chrono::duration<double, std::milli>(t1 - t0).count();
        both_ms += std::chrono::duration<double, std::milli>(t2 - t0).count();
      }
    }
    std::printf("| %dx%d %s D=%d C=%d | %s | %.3f | %.3f |\n", width, height, device_name.c_str(),
                features, classes, took_fused ? "yes" : "no", fwd_ms / repeats, both_ms / repeats);
  }
  return 0;
}
