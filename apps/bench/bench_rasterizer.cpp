// Rasterizer benchmark (a program, not a test): forward and forward+backward time of render()
// for random in-frustum Gaussians, on CPU or CUDA. Prints one table row per configuration.
//   sadsplat_bench_rasterizer [--device cpu|cuda] [--gaussians 100000,500000,1000000]
//                             [--features 0,32] [--width 800] [--height 450] [--repeats 20]
//                             [--profile]
// --profile adds, per configuration, the time of each step of the rasterizer (projection, SH,
// binning, sort, rasterization and their backward passes) from `repeats` more iterations in which
// every step waits for the device (see step_profile.h), and the peak device memory.
#include <CLI/CLI.hpp>

#include <ATen/Context.h>
#include <ATen/Parallel.h>
#include <c10/core/GradMode.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "bench_support.h"
#include "sadsplat/gaussians/cpu_threads.h"
#include "sadsplat/gaussians/rasterizer.h"
#include "sadsplat/gaussians/step_profile.h"
#include "sadsplat/gaussians/device.h"

namespace {

using sadsplat::gaussians::GaussianParams;

// Gaussians uniformly in the camera frustum between depths 2 and 10.
GaussianParams randomInFrustum(int64_t n, int64_t features,
                               const sadsplat::gaussians::RasterCamera& cam,
                               const at::Device& device) {
  at::manual_seed(0);
  const auto opts = at::TensorOptions().dtype(at::kFloat);
  const at::Tensor z = 2.0 + 8.0 * at::rand({n, 1}, opts);
  const at::Tensor u = at::rand({n, 1}, opts) * cam.width, v = at::rand({n, 1}, opts) * cam.height;
  GaussianParams g;
  g.means = at::cat({(u - cam.cx) / cam.fx * z, (v - cam.cy) / cam.fy * z, z}, 1);
  g.quats = at::randn({n, 4}, opts);
  g.log_scales = at::log(0.01 + 0.025 * at::rand({n, 3}, opts));
  g.opacity_logits = at::randn({n}, opts);
  g.sh = at::randn({n, 16, 3}, opts) * 0.2;
  g.features = at::randn({n, features}, opts);
  for (at::Tensor* t : {&g.means, &g.quats, &g.log_scales, &g.opacity_logits, &g.sh, &g.features}) {
    *t = t->to(device).requires_grad_(true);
  }
  return g;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"sadsplat rasterizer benchmark"};
  std::string device_name = "cpu";
  std::vector<int64_t> counts = {100000, 500000, 1000000};
  std::vector<int64_t> feature_dims = {0, 32};
  int width = 800, height = 450, repeats = 20, warmup = 3;
  int threads = static_cast<int>(std::thread::hardware_concurrency());
  app.add_option("--device", device_name, "cpu or cuda")->capture_default_str();
  app.add_option("--gaussians", counts, "Gaussian counts")->delimiter(',');
  app.add_option("--features", feature_dims, "feature channel counts")->delimiter(',');
  app.add_option("--width", width)->capture_default_str();
  app.add_option("--height", height)->capture_default_str();
  app.add_option("--repeats", repeats)->capture_default_str();
  app.add_option("--warmup", warmup)->capture_default_str();
  app.add_option("--threads", threads, "CPU threads")->capture_default_str();
  bool profile_steps = false;
  app.add_flag("--profile", profile_steps, "also time each step of the rasterizer");
  CLI11_PARSE(app, argc, argv);
  sadsplat::gaussians::setCpuThreads(std::max(1, threads));
  const at::Device device = sadsplat::gaussians::deviceNamed(device_name, "--device");
  if (device.is_cuda() && !at::hasCUDA()) {
    std::fprintf(stderr, "sadsplat_bench_rasterizer: no CUDA device\n");
    return 1;
  }
  sadsplat::gaussians::RasterCamera cam;
  cam.width = width;
  cam.height = height;
  cam.fx = cam.fy = 0.8 * width;
  cam.cx = width / 2.0;
  cam.cy = height / 2.0;
  using Clock = std::chrono::steady_clock;
  std::printf("device=%s threads=%d image=%dx%d repeats=%d\n", device_name.c_str(),
              at::get_num_threads(), width, height, repeats);
  std::printf(
      "| gaussians | features | tile hits / gaussian | forward ms | forward+backward ms |\n");
  std::printf("|---|---|---|---|---|\n");
  std::string profiles;  // --profile: printed after the timing table
  for (int64_t n : counts) {
    for (int64_t c : feature_dims) {
      const GaussianParams g = randomInFrustum(n, c, cam, device);
      double fwd_ms = 0, both_ms = 0;
      double tiles_per_gaussian = 0;
      for (int it = 0; it < warmup + repeats; ++it) {
        sadsplat::bench::synchronize(device);
        const auto t0 = Clock::now();
        sadsplat::gaussians::RenderResult r;
        {
          c10::AutoGradMode no_grad(false);
          r = sadsplat::gaussians::render(g, cam);
        }
        sadsplat::bench::synchronize(device);
        const auto t1 = Clock::now();
        const auto r2 = sadsplat::gaussians::render(g, cam);
        (r2.rgb.sum() + r2.features.sum()).backward();
        sadsplat::bench::synchronize(device);
        const auto t2 = Clock::now();
        if (it >= warmup) {
          fwd_ms += std::chrono::duration<double, std::milli>(t1 - t0).count();
          both_ms += std::chrono::duration<double, std::milli>(t2 - t1).count();
        }
        if (it == 0) {
          // Tiles of the visible Gaussians' 3-sigma square boxes (an upper bound: the binning cuts
          // each box to where its alpha can reach 1/255, raster::alphaBox).
          const at::Tensor radii = r.radii.to(at::kCPU).to(at::kFloat);
          const at::Tensor span = (2.0 * radii / 16.0 + 1.0).floor();
          tiles_per_gaussian = (span * span).sum().item<double>() / static_cast<double>(n);
        }
      }
      std::printf("| %lld | %lld | ~%.1f | %.2f | %.2f |\n", static_cast<long long>(n),
                  static_cast<long long>(c), tiles_per_gaussian, fwd_ms / repeats,
                  both_ms / repeats);
      std::fflush(stdout);
      if (profile_steps) {
        sadsplat::gaussians::StepProfile profile(device);
        const sadsplat::gaussians::ActiveProfileScope active(&profile);
        for (int it = 0; it < repeats; ++it) {
          profile.enter("forward+backward: forward");
          const auto r2 = sadsplat::gaussians::render(g, cam);
          profile.enter("forward+backward: backward");
          (r2.rgb.sum() + r2.features.sum()).backward();
          profile.leave();
          profile.countIteration();
        }
        profiles += "\nSteps of forward+backward, " + std::to_string(n) + " Gaussians, " +
                    std::to_string(c) + " features:\n\n" + profile.table();
      }
    }
  }
  std::printf("%s", profiles.c_str());
  return 0;
}
