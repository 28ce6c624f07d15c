#include "sadsplat/eval/evaluation.h"

#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <limits>

#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/image_metrics.h"
#include "sadsplat/gaussians/view_coverage.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/scene_cache.h"

#if SADSPLAT_HAVE_OPENCV
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#endif

namespace sadsplat {
namespace eval {
namespace {

#if SADSPLAT_HAVE_OPENCV
cv::Mat classImage(const std::vector<std::uint8_t>& ids, int W, int H,
                   const std::vector<ClassInfo>& classes) {
  cv::Mat out(H, W, CV_8UC3);
  for (int i = 0; i < W * H; ++i) {
    const auto id = ids[i];
    cv::Vec3b c(0, 0, 0);
    if (id < classes.size())
      c = {classes[id].color[0], classes[id].color[1],
           classes[id].color[2]};  // RGB; the panel is converted to BGR once
    out.at<cv::Vec3b>(i / W, i % W) = c;
  }
  return out;
}

void writePanel(const std::string& path, const io::View& view, const at::Tensor& render_rgb,
                const std::vector<std::uint8_t>& labels, const std::vector<std::uint8_t>& pred,
                const std::vector<ClassInfo>& classes) {
  const int W = view.camera.width, H = view.camera.height;
  cv::Mat image(H, W, CV_8UC3, const_cast<std::uint8_t*>(view.rgb.pixels.data()));
  const at::Tensor bytes =
      render_rgb.clamp(0, 1).mul(255).round().to(at::kByte).to(at::kCPU).contiguous();
  cv::Mat render(H, W, CV_8UC3, bytes.data_ptr<std::uint8_t>());
  cv::Mat error(H, W, CV_8UC3);
  for (int i = 0; i < W * H; ++i) {
    const auto gt = labels[i];
    error.at<cv::Vec3b>(i / W, i % W) =
        gt == io::kIgnoreLabel ? cv::Vec3b(60, 60, 60)
                               : (gt == pred[i] ? cv::Vec3b(255, 255, 255) : cv::Vec3b(255, 0, 0));
  }
  cv::Mat panel;
  if (classes.empty()) {
    cv::hconcat(std::vector<cv::Mat>{image, render}, panel);  // no classes: image | render
  } else {
    cv::hconcat(std::vector<cv::Mat>{image, render, classImage(labels, W, H, classes),
                                     classImage(pred, W, H, classes), error},
                panel);
  }
  cv::Mat bgr;
  cv::cvtColor(panel, bgr, cv::COLOR_RGB2BGR);
  std::vector<std::uint8_t> png;
  cv::imencode(".png", bgr, png);
  io::writeFileAtomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  });
}
#endif

// The cameras of every view of the scene, or of its training views only.
std::vector<gaussians::RasterCamera> camerasOf(const io::Scene& scene, bool training_only) {
  std::vector<gaussians::RasterCamera> cameras;
  for (const io::View& v : scene.views) {
    if (v.train || !training_only)
      cameras.push_back(gaussians::RasterCamera::fromPinhole(v.camera));
  }
  return cameras;
}

// Coverage is counted once per 4 x 4 pixels (the sparse depth is per 32 x 32): 16 times less
// work for surveys of many large photos.
constexpr int kCoverageStride = 4;

}  // namespace

FloaterCensus countFloaters(const gaussians::Trainer& trainer, const io::Scene& scene) {
  const std::vector<gaussians::RasterCamera> all = camerasOf(scene, false);
  const std::vector<gaussians::RasterCamera> training = camerasOf(scene, true);
  const gaussians::GaussianParams g = trainer.parameters();
  FloaterCensus census;
  census.extent = gaussians::sceneExtent(all);
  const auto count = [](const at::Tensor& mask) { return mask.sum().item<std::int64_t>(); };
  census.larger_than_2pct =
      count(gaussians::floaterMask(g.means, g.log_scales, training, 0, 0.02 * census.extent));
  census.larger_than_10pct =
      count(gaussians::floaterMask(g.means, g.log_scales, training, 0, 0.1 * census.extent));
  census.seen_by_under_2_views =
      count(gaussians::floaterMask(g.means, g.log_scales, training, 2, 0));
  return census;
}

namespace {

// The pixels of `view` whose surface at least kCoveredMinViews training views see. The surface
// depth is the capture's (its sparse points) where a point falls into the view, so that every
// model is scored on the same pixels; else the model's own (then *from_sparse is false).
at::Tensor coveredPixels(const io::View& view, const gaussians::RenderResult& r,
                         const at::Tensor& points,
                         const std::vector<gaussians::RasterCamera>& training, bool* from_sparse) {
  const gaussians::RasterCamera camera = gaussians::RasterCamera::fromPinhole(view.camera);
  const at::Tensor sparse =
      points.defined() ? gaussians::sparseDepthImage(points, camera) : at::Tensor();
  *from_sparse = sparse.defined();
  const at::Tensor counts =
      sparse.defined()
          ? gaussians::pixelViewCounts(sparse.to(r.rgb.device()), at::ones_like(r.alpha), camera,
                                       training, 0.5, kCoverageStride)
          : gaussians::pixelViewCounts(r.depth, r.alpha, camera, training, 0.5, kCoverageStride);
  return counts.ge(kCoveredMinViews);
}

}  // namespace

EvalResult evaluate(const gaussians::Trainer& trainer, const io::Scene& scene,
                    const std::string& panel_dir) {
  EvalResult result;
  result.floaters = countFloaters(trainer, scene);
  result.confusion = ConfusionMatrix(static_cast<int>(scene.classes.size()));
  bool any_test = false;
  for (const auto& v : scene.views) any_test = any_test || v.test;
  double psnr_sum = 0, ssim_sum = 0, render_seconds = 0;
  double covered_psnr_sum = 0, covered_pixels = 0, evaluated_pixels = 0;
  int covered_views = 0;
  const std::vector<gaussians::RasterCamera> training = camerasOf(scene, true);
  const at::Tensor points = gaussians::sparsePointTensor(scene);
  result.covered_depth = "sparse points";
  const bool semantic = !scene.classes.empty();
  for (const io::View& listed : scene.views) {
    if (any_test && !listed.test) continue;
    // A view whose pixels wait in the scene cache is read now: one view in memory at a time.
    io::View read;
    if (listed.pixels_in_cache) read = io::readViewPixels(listed);
    const io::View& view = listed.pixels_in_cache ? read : listed;
    const gaussians::RenderResult r = trainer.renderView(view);
    {
      // Render time: r was the warm-up; reading a value back waits for the device.
      constexpr int kRepeats = 3;
      const auto t0 = std::chrono::steady_clock::now();
      for (int k = 0; k < kRepeats; ++k) trainer.renderView(view).alpha.sum().item<float>();
      render_seconds +=
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() / kRepeats;
    }
    const std::size_t pixels = static_cast<std::size_t>(view.camera.width) * view.camera.height;
    // Ignore everywhere when the view has no label map: the image metrics still count.
    std::vector<std::uint8_t> labels = view.labels.empty()
                                           ? std::vector<std::uint8_t>(pixels, io::kIgnoreLabel)
                                           : view.labels.pixels;
    std::vector<std::uint8_t> pred8(pixels, io::kIgnoreLabel);
    if (semantic) {
      const at::Tensor pred = trainer.predictClasses(r).to(at::kCPU).contiguous();
      const std::int64_t* p = pred.data_ptr<std::int64_t>();
      for (std::size_t i = 0; i < pixels; ++i) pred8[i] = static_cast<std::uint8_t>(p[i]);
    }
    for (std::size_t i = 0; i < labels.size(); ++i) {
      if (view.mask.pixels[i] == 0) labels[i] = io::kIgnoreLabel;
    }
    ViewScore score;
    score.name = view.name;
    score.accuracy = std::numeric_limits<double>::quiet_NaN();
    if (semantic && !view.labels.empty()) {
      std::vector<std::int64_t> pred64(pred8.begin(), pred8.end());
      ConfusionMatrix confusion(result.confusion.numClasses());
      confusion.add(labels.data(), pred64.data(), labels.size());
      if (confusion.total() > 0) score.accuracy = confusion.overallAccuracy();
      result.confusion.add(confusion);
      ++result.labelled_views;
    }
    const int W = view.camera.width, H = view.camera.height;
    const at::Tensor gt = at::from_blob(const_cast<std::uint8_t*>(view.rgb.pixels.data()),
                                        {H, W, 3}, at::TensorOptions().dtype(at::kByte))
                              .to(at::kFloat)
                              .div(255.0)
                              .to(r.rgb.device());
    const at::Tensor rgb = r.rgb.clamp(0, 1);
    score.psnr = gaussians::psnr(rgb, gt);
    psnr_sum += score.psnr;
    {
      const at::Tensor inside = at::from_blob(const_cast<std::uint8_t*>(view.mask.pixels.data()),
                                              {H, W}, at::TensorOptions().dtype(at::kByte))
                                    .to(r.rgb.device())
                                    .gt(0);
      bool from_sparse = true;
      const at::Tensor covered = coveredPixels(view, r, points, training, &from_sparse) & inside;
      if (!from_sparse) result.covered_depth = "model";
      const double n = covered.sum().item<double>();
      evaluated_pixels += inside.sum().item<double>();
      covered_pixels += n;
      if (n > 0) {
        const double mse = ((rgb - gt).pow(2).sum(2) * covered).sum().item<double>() / (3.0 * n);
        covered_psnr_sum += mse > 0 ? -10.0 * std::log10(mse) : 99.0;
        ++covered_views;
      }
    }
    score.ssim = gaussians::ssim(rgb, gt).item<double>();
    ssim_sum += score.ssim;
    result.views.push_back(view.name);
    result.per_view.push_back(score);
#if SADSPLAT_HAVE_OPENCV
    if (!panel_dir.empty()) {
      const std::string stem = view.name.substr(0, view.name.find_last_of('.'));
      writePanel(panel_dir + "/" + stem + ".png", view, rgb, labels, pred8, scene.classes);
    }
#endif
  }
  if (result.views.empty()) {
    throw Error(scene.source, "test views", "at least one view to evaluate", "none");
  }
  result.held_out = any_test;
  if (!semantic) {
    result.miou_note = "no classes (the scene has no classes.json): image metrics only";
  } else if (result.labelled_views == 0) {
    result.miou_note = std::string("no label map on any ") + (any_test ? "test" : "") +
                       " view: add labels/ (or import annotations) for mIoU";
  }
  result.psnr = psnr_sum / result.views.size();
  result.ssim = ssim_sum / result.views.size();
  result.psnr_covered = covered_views > 0 ? covered_psnr_sum / covered_views
                                          : std::numeric_limits<double>::quiet_NaN();
  result.covered_fraction = evaluated_pixels > 0 ? covered_pixels / evaluated_pixels : 0.0;
  result.render_ms = 1000.0 * render_seconds / result.views.size();
  return result;
}

std::string metricsJson(const EvalResult& r, const std::vector<ClassInfo>& classes,
                        const RunFacts& facts) {
  nlohmann::json perView = nlohmann::json::array();
  for (const ViewScore& v : r.per_view) {
    perView.push_back({{"name", v.name},
                       {"psnr", v.psnr},
                       {"ssim", v.ssim},
                       {"accuracy", std::isnan(v.accuracy) ? nlohmann::json(nullptr)
                                                           : nlohmann::json(v.accuracy)}});
  }
  nlohmann::json per_class = nlohmann::json::object();
  const auto iou = r.confusion.perClassIou();
  for (std::size_t c = 0; c < classes.size(); ++c) {
    per_class[classes[c].name] = iou[c] >= 0 ? nlohmann::json(iou[c]) : nlohmann::json(nullptr);
  }
  nlohmann::json matrix = nlohmann::json::array();
  for (int g = 0; g < r.confusion.numClasses(); ++g) {
    nlohmann::json row = nlohmann::json::array();
    for (int p = 0; p < r.confusion.numClasses(); ++p) row.push_back(r.confusion.at(g, p));
    matrix.push_back(row);
  }
  nlohmann::json names = nlohmann::json::array();
  for (const auto& c : classes) names.push_back(c.name);
  // No labelled pixel scored: the class metrics are null (not 0) and the note says why.
  const bool scored = r.miou_note.empty();
  const auto metric = [&](double v) {
    return scored ? nlohmann::json(v) : nlohmann::json(nullptr);
  };
  const nlohmann::json j = {
      {"miou", metric(r.confusion.meanIou())},
      {"macc", metric(r.confusion.meanAccuracy())},
      {"oacc", metric(r.confusion.overallAccuracy())},
      {"miou_note", scored ? nlohmann::json(nullptr) : nlohmann::json(r.miou_note)},
      {"labelled_views", r.labelled_views},
      {"held_out", r.held_out},
      {"per_class_iou", per_class},
      {"psnr", r.psnr},
      {"ssim", r.ssim},
      {"psnr_covered",
       std::isnan(r.psnr_covered) ? nlohmann::json(nullptr) : nlohmann::json(r.psnr_covered)},
      {"covered_fraction", r.covered_fraction},
      {"covered_min_views", kCoveredMinViews},
      {"covered_depth", r.covered_depth},
      {"num_gaussians", facts.num_gaussians},
      {"render_ms", r.render_ms},
      {"floaters",
       {{"scene_extent", r.floaters.extent},
        {"larger_than_2pct_extent", r.floaters.larger_than_2pct},
        {"larger_than_10pct_extent", r.floaters.larger_than_10pct},
        {"seen_by_under_2_training_views", r.floaters.seen_by_under_2_views}}},
      {"iterations", facts.iterations},
      {"train_seconds", facts.train_seconds},
      {"device", facts.device},
      {"classes", names},
      {"confusion_matrix", matrix},
      {"views", r.views},
      {"per_view", perView}};
  return j.dump(2) + "\n";
}

}  // namespace eval
}  // namespace sadsplat
