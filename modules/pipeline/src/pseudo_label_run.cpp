#include "sadsplat/pipeline/pseudo_label_run.h"

#include <chrono>
#include <sstream>

#include <nlohmann/json.hpp>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/pipeline/opened_run.h"
#include "sadsplat/pseudo_labels/quality_report.h"
#include "sadsplat/pseudo_labels/torchscript_scorer.h"

#if SADSPLAT_HAVE_OPENCV
#include <opencv2/imgcodecs.hpp>
#endif

namespace sadsplat {
namespace pipeline {
namespace {

#if SADSPLAT_HAVE_OPENCV
// Image | pseudo-labels (class colours where kept, grey where a target was filtered out) |
// ground truth where the view has it.
void writeOverlay(const std::string& path, const io::View& v,
                  const std::vector<ClassInfo>& classes) {
  const int W = v.camera.width, H = v.camera.height;
  const bool gt = !v.labels.empty();
  cv::Mat out(H, W * (gt ? 3 : 2), CV_8UC3, cv::Scalar(0, 0, 0));
  const std::vector<std::int16_t> label = v.pseudo.labelMap();
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * W + x;
      const std::uint8_t* p = &v.rgb.pixels[3 * i];
      out.at<cv::Vec3b>(y, x) = cv::Vec3b(p[2], p[1], p[0]);
      cv::Vec3b c(0, 0, 0);
      if (label[i] >= 0) {
        const auto& k = classes[label[i]].color;
        c = cv::Vec3b(k[2] / 2 + p[2] / 2, k[1] / 2 + p[1] / 2, k[0] / 2 + p[0] / 2);
      } else if (v.pseudo.region[i] >= 0) {
        const std::uint8_t g = static_cast<std::uint8_t>((p[0] + p[1] + p[2]) / 9);
        c = cv::Vec3b(g, g, g);
      }
      out.at<cv::Vec3b>(y, W + x) = c;
      if (gt) {
        const int l = v.labels.pixels[i];
        if (l < static_cast<int>(classes.size())) {
          const auto& k = classes[l].color;
          out.at<cv::Vec3b>(y, 2 * W + x) = cv::Vec3b(k[2], k[1], k[0]);
        }
      }
    }
  }
  std::vector<std::uint8_t> png;
  cv::imencode(".png", out, png);
  io::writeFileAtomically(path, [&](std::ostream& o) {
    o.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  });
}
#endif

// What the run did, for report.json: the filter, the counts and both checks, per class.
nlohmann::json generationJson(const pseudo_labels::PseudoLabelSummary& s,
                              const pseudo_labels::PseudoLabelOptions& filter,
                              const std::vector<ClassInfo>& classes) {
  nlohmann::json g = {{"backend", s.backend},
                      {"views", s.views},
                      {"filter", filter.per_class ? "per-class" : "paper"},
                      {"filter_k", filter.filter_k},
                      {"min_view_agreement", filter.min_view_agreement},
                      {"min_class_precision", filter.min_class_precision},
                      {"targets", s.targets},
                      {"kept_targets", s.kept_targets},
                      {"kept_regions", s.kept_regions}};
  nlohmann::json per_class = nlohmann::json::object();
  for (std::size_t c = 0; c < classes.size(); ++c) {
    nlohmann::json e = nlohmann::json::object();
    if (c < s.view_check_removed.size()) e["cross_view_unkept"] = s.view_check_removed[c];
    if (c < s.check_pixels.size()) {
      e["labelled_view_check_pixels"] = s.check_pixels[c];
      e["labelled_view_check_correct"] = s.check_correct[c];
      e["removed_by_class_check"] = static_cast<bool>(s.class_rejected[c]);
    }
    per_class[classes[c].name] = e;
  }
  g["classes"] = per_class;
  return g;
}

// A class no annotated photo shows cannot be learnt: say so before the long work, by name.
void warnOfUnannotatedClasses(const io::Scene& scene, std::ostream* progress) {
  int views = 0;
  const std::vector<std::int64_t> pixels = io::annotatedPixelsPerClass(scene, &views);
  if (progress == nullptr || views == 0) return;
  std::string missing;
  for (std::size_t c = 0; c < pixels.size(); ++c) {
    if (pixels[c] == 0) missing += (missing.empty() ? "" : ", ") + scene.classes[c].name;
  }
  if (missing.empty()) return;
  *progress << "warning: no annotated photo (" << views << " labelled training views) shows "
            << missing << ": neither the annotations nor the pseudo-labels can teach "
            << (missing.find(',') == std::string::npos ? "it" : "them")
            << "; annotate a photo where each appears (`sadsplat pick-views SCENE "
               "--keep-labelled` names photos that see the ground the annotated ones do not)\n";
}

}  // namespace

std::string pseudoLabelRun(const PseudoLabelRunOptions& o) {
  const bool input_is_cache = !io::isDirectory(o.scene);
  const std::string out = o.out.empty() ? (input_is_cache ? o.scene : "") : o.out;
  if (out.empty()) {
    throw Error(o.scene, "--out", "a scene cache file to write (the input is a scene directory)",
                "no --out");
  }
  io::Scene scene = loadScene(o.scene, o.scale);
  warnOfUnannotatedClasses(scene, o.progress);
  pseudo_labels::TargetScorer::Ptr scorer;
  if (o.backend == "builtin") {
    scorer = pseudo_labels::makeBuiltinScorer(o.builtin);
  } else if (o.backend == "torchscript") {
    if (o.sam_model.empty() || o.clip_model.empty()) {
      throw Error("<command line>", "--backend torchscript", "--sam FILE and --clip FILE",
                  "--sam and --clip not both given");
    }
    scorer = pseudo_labels::makeTorchScriptScorer(o.sam_model, o.clip_model);
  } else {
    throw Error("<command line>", "--backend", "builtin or torchscript", o.backend);
  }
  const auto start = std::chrono::steady_clock::now();
  pseudo_labels::ProgressFn progress;
  if (o.progress)
    progress = [&](const std::string& line) { *o.progress << "  " << line << "\n" << std::flush; };
  const pseudo_labels::PseudoLabelSummary s =
      pseudo_labels::generatePseudoLabels(scene, *scorer, o.filter, progress);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  io::writeSceneCache(out, scene);
  if (o.progress) {
    const double k = o.filter.filter_k;
    auto thresholds = [k](const pseudo_labels::TargetStatistics& t) {
      std::ostringstream line;
      line << "TOP1 > " << t.top1_mean + k * t.top1_std << ", dTOP > "
           << t.delta_top_mean + k * t.delta_top_std << ", entropy < "
           << t.entropy_mean + k * t.entropy_std;
      return line.str();
    };
    *o.progress << s.backend << ": " << s.views << " training views, " << s.targets << " targets, "
                << s.kept_targets << " kept ("
                << (s.class_statistics.empty() ? thresholds(s.statistics) : "per TOP1 class")
                << ") in " << seconds << " s; wrote " << out << "\n";
    for (std::size_t c = 0; c < s.check_pixels.size(); ++c) {
      if (s.check_pixels[c] == 0) continue;
      *o.progress << "  check on the labelled views: " << scene.classes[c].name << " "
                  << 100.0 * s.check_correct[c] / s.check_pixels[c] << " % of " << s.check_pixels[c]
                  << " kept pixels right"
                  << (s.class_rejected[c] ? " -> pseudo-labels of this class removed" : "") << "\n";
    }
    if (!s.view_check_removed.empty() && scene.points.empty()) {
      *o.progress << "  cross-view check skipped: the scene has no sparse points\n";
    } else if (!s.view_check_removed.empty()) {
      *o.progress << "  cross-view check (agreement < " << o.filter.min_view_agreement
                  << ") unkept:";
      for (std::size_t c = 0; c < s.view_check_removed.size(); ++c) {
        *o.progress << " " << scene.classes[c].name << " " << s.view_check_removed[c];
      }
      *o.progress << " regions\n";
    }
    if (s.kept_regions != s.kept_targets) {
      *o.progress << "  stored: " << s.kept_regions
                  << " kept regions (overlaps resolved, removed by the checks)\n";
    }
    if (s.kept_regions == 0) {
      *o.progress << "warning: no kept target is left, so no view gets pseudo-labels "
                     "(training will use the ground truth only); try a smaller --filter-k\n";
    }
    for (std::size_t c = 0; c < s.class_statistics.size(); ++c) {
      *o.progress << "  " << scene.classes[c].name << ": " << thresholds(s.class_statistics[c])
                  << "\n";
    }
  }
  if (o.report_dir.empty()) return "";
  io::makeDirectory(o.report_dir);
  const pseudo_labels::PseudoLabelQuality q = pseudo_labels::evaluatePseudoLabels(scene);
  const std::string text = q.toText();
  nlohmann::json report = nlohmann::json::parse(q.toJson());
  report["generation"] = generationJson(s, o.filter, scene.classes);
  io::writeFileAtomically(o.report_dir + "/report.json",
                          [&](std::ostream& f) { f << report.dump(2) << "\n"; });
  io::writeFileAtomically(o.report_dir + "/report.txt", [&](std::ostream& f) { f << text; });
#if SADSPLAT_HAVE_OPENCV
  io::makeDirectory(o.report_dir + "/overlays");
  int written = 0;
  for (const io::View& v : scene.views) {
    if (v.pseudo.empty() || written >= 6) continue;
    writeOverlay(o.report_dir + "/overlays/" + v.name + ".png", v, scene.classes);
    ++written;
  }
#endif
  return text;
}

}  // namespace pipeline
}  // namespace sadsplat
