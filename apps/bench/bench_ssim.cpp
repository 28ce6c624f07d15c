// SSIM loss benchmark (a program, not a test): forward and forward+backward time of the fused
// SSIM against the reference composition (separable convolutions), same images, same run.
//   sadsplat_bench_ssim [--device cuda|cpu] [--width 800] [--height 450] [--repeats 50]
#include <CLI/CLI.hpp>

#include <ATen/Context.h>
#include <torch/csrc/autograd/autograd.h>

#include <chrono>
#include <cstdio>
#include <string>

#include "bench_support.h"
#include "sadsplat/gaussians/image_metrics.h"
#include "sadsplat/gaussians/device.h"

int main(int argc, char** argv) {
  CLI::App app{"SSIM loss: fused vs reference, forward and forward+backward"};
  std::string device_name = "cuda";
  int width = 800, height = 450, repeats = 50;
  app.add_option("--device", device_name, "cpu or cuda")->capture_default_str();
  app.add_option("--width", width)->capture_default_str();
  app.add_option("--height", height)->capture_default_str();
  app.add_option("--repeats", repeats)->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (device_name == "cuda" && !at::hasCUDA()) {
    std::fprintf(stderr, "no CUDA device\n");
    return 1;
  }
  const at::Device device = sadsplat::gaussians::deviceNamed(device_name, "--device");
  at::manual_seed(0);
  const auto opts = at::TensorOptions().dtype(at::kFloat).device(device);
  const at::Tensor target = at::rand({height, width, 3}, opts);
  const at::Tensor image = (target * 0.8 + 0.2 * at::rand({height, width, 3}, opts)).detach();
  std::printf("| variant | fused | forward ms | forward+backward ms |\n|---|---|---|---|\n");
  using Clock = std::chrono::steady_clock;
  for (const bool fused : {false, true}) {
    double fwd_ms = 0, both_ms = 0;
    for (int r = -3; r < repeats; ++r) {
      const at::Tensor a = image.clone().requires_grad_(true);
      sadsplat::bench::synchronize(device);
      const auto t0 = Clock::now();
      at::Tensor value = fused ? sadsplat::gaussians::ssim(a, target)
                               : sadsplat::gaussians::ssimReference(a, target);
      sadsplat::bench::synchronize(device);
      const auto t1 = Clock::now();
      torch::autograd::grad({value}, {a});
      sadsplat::bench::synchronize(device);
      const auto t2 = Clock::now();
      if (r >= 0) {
        fwd_ms += std::chrono::duration<double, std::milli>(t1 - t0).count();
        both_ms += std::chrono::duration<double, std::milli>(t2 - t0).count();
      }
    }
    std::printf("| %dx%d %s | %s | %.3f | %.3f |\n", width, height, device_name.c_str(),
                fused && sadsplat::gaussians::ssimIsFused(image, target) ? "yes" : "no",
                fwd_ms / repeats, both_ms / repeats);
  }
  return 0;
}
