#include "sadsplat/viz/training_report.h"

#include <nlohmann/json.hpp>

#include "json_text.h"
#include "short_name.h"

#include <algorithm>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/run_directory.h"
#include "sadsplat/io/train_log.h"
#include "sadsplat/viz/chart_png.h"

namespace sadsplat {
namespace viz {
namespace {

namespace fs = std::filesystem;

struct RunFacts {
  std::string dir;
  std::string name;
  std::vector<io::TrainLogRecord> log;
  nlohmann::json metrics;  // null when the run was not evaluated
};

RunFacts loadRun(const std::string& dir) {
  if (!io::isDirectory(dir)) {
    throw Error(dir, "run directory", "a directory written by `sadsplat train`",
                "no such directory");
  }
  RunFacts r;
  r.dir = dir;
  r.name = shortName(dir);
  const io::RunDirectory files(dir);
  const std::string log = files.trainLog();
  if (!io::isRegularFile(log)) {
    throw Error(log, "file", "the train log that `sadsplat train` writes", "missing");
  }
  r.log = io::readTrainLog(log);
  const std::string metrics = files.metrics();
  if (io::isRegularFile(metrics)) {
    r.metrics = parseOrDiscard(io::readWholeFile(metrics));
    if (r.metrics.is_discarded() || !r.metrics.is_object()) {
      throw Error(metrics, "JSON", "the object `sadsplat eval` writes", "unparsable text");
    }
  }
  return r;
}

ChartSeries series(const std::string& name, std::array<std::uint8_t, 3> color,
                   bool markers = false) {
  ChartSeries s;
  s.name = name;
  s.color = color;
  s.markers_only = markers;
  return s;
}

std::string number(const nlohmann::json& m, const char* key, double scale, int precision) {
  if (m.is_null() || !m.contains(key) || !m[key].is_number()) return "-";
  std::ostringstream out;
  out << std::fixed << std::setprecision(precision) << scale * m[key].get<double>();
  return out.str();
}

}  // namespace

std::string writeTrainingReport(const ReportOptions& options) {
  const RunFacts run = loadRun(options.run);
  std::unique_ptr<RunFacts> base;
  if (!options.baseline.empty()) base = std::make_unique<RunFacts>(loadRun(options.baseline));
  const std::string out =
      options.out.empty() ? (fs::path(options.run) / "report").string() : options.out;
  io::makeDirectory(out);
  const auto file = [&](const char* name) { return (fs::path(out) / name).string(); };

  // Loss terms.
  ChartSeries total = series("total " + run.name, {31, 119, 180});
  ChartSeries rgb = series("rgb", {44, 160, 44});
  ChartSeries sem = series("semantic", {214, 39, 40});
  ChartSeries rest = series("rest (L0, ...)", {148, 103, 189});
  ChartSeries count = series(run.name, {31, 119, 180});
  ChartSeries drops = series("drop events", {214, 39, 40}, true);
  ChartSeries cap = series("max_gaussians reached", {148, 103, 189}, true);
  for (const auto& r : run.log) {
    if (r.type == "step") {
      total.x.push_back(r.iteration);
      total.y.push_back(r.loss);
      rgb.x.push_back(r.iteration);
      rgb.y.push_back(r.rgb_loss);
      sem.x.push_back(r.iteration);
      sem.y.push_back(r.semantic_loss);
      rest.x.push_back(r.iteration);
      rest.y.push_back(r.loss - r.rgb_loss - r.semantic_loss);
    }
    if (r.type == "step" || r.type == "drop" || r.type == "closed_gates" || r.type == "recovery") {
      count.x.push_back(r.iteration);
      count.y.push_back(static_cast<double>(r.gaussians));
    }
    if (r.type == "drop" || r.type == "closed_gates" || r.type == "recovery") {
      drops.x.push_back(r.iteration);
      drops.y.push_back(static_cast<double>(r.gaussians));
    }
    if (r.type == "max_gaussians_reached") {
      cap.x.push_back(r.iteration);
      cap.y.push_back(static_cast<double>(r.gaussians));
    }
  }
  if (total.x.empty()) {
    throw Error(io::RunDirectory(run.dir).trainLog(), "records", "at least one step record",
                "none");
  }
  std::vector<ChartSeries> loss_series = {total, rgb, sem, rest};
  std::vector<ChartSeries> count_series = {count, drops};
  if (!cap.x.empty()) count_series.push_back(cap);
  if (base) {
    ChartSeries base_total = series("total " + base->name, {255, 127, 14});
    ChartSeries base_count = series(base->name, {255, 127, 14});
    for (const auto& r : base->log) {
      if (r.type != "step") continue;
      base_total.x.push_back(r.iteration);
      base_total.y.push_back(r.loss);
      base_count.x.push_back(r.iteration);
      base_count.y.push_back(static_cast<double>(r.gaussians));
    }
    loss_series.push_back(base_total);
    count_series.push_back(base_count);
  }
  writeLineChart(file("loss.png"), {"Training loss", "iteration", "loss", 900, 500, false},
                 loss_series);
  writeLineChart(
      file("gaussians.png"),
      {"Gaussians (drop events and the cap marked)", "iteration", "Gaussians", 900, 500, false},
      count_series);

  // Per-class IoU.
  bool have_iou = false;
  if (!run.metrics.is_null() && run.metrics.contains("per_class_iou") &&
      run.metrics.contains("classes")) {
    std::vector<std::string> classes;
    ChartSeries iou = series(run.name, {31, 119, 180});
    ChartSeries base_iou = series(base ? base->name : "", {255, 127, 14});
    for (const auto& c : run.metrics["classes"]) {
      const std::string name = c.get<std::string>();
      classes.push_back(name);
      const auto& per = run.metrics["per_class_iou"];
      iou.y.push_back(per.contains(name) && per[name].is_number() ? 100 * per[name].get<double>()
                                                                  : 0.0);
      if (base && !base->metrics.is_null() && base->metrics.contains("per_class_iou")) {
        const auto& bper = base->metrics["per_class_iou"];
        base_iou.y.push_back(
            bper.contains(name) && bper[name].is_number() ? 100 * bper[name].get<double>() : 0.0);
      }
    }
    std::vector<ChartSeries> bars = {iou};
    if (base_iou.y.size() == classes.size()) bars.push_back(base_iou);
    writeBarChart(file("per_class_iou.png"),
                  {"IoU per class (test views)", "class", "IoU (%)", 900, 500, false}, classes,
                  bars);
    have_iou = true;
  }

  // report.md
  std::ostringstream md;
  md << "# Training report: " << run.name << "\n\n";
  md << "| | " << run.name << (base ? " | " + base->name : "") << " |\n|---|---|"
     << (base ? "---|" : "") << "\n";
  const nlohmann::json none;
  const auto row = [&](const char* label, const char* key, double scale, int precision) {
    md << "| " << label << " | " << number(run.metrics, key, scale, precision);
    if (base) md << " | " << number(base->metrics, key, scale, precision);
    md << " |\n";
  };
  row("mIoU (%)", "miou", 100, 2);
  row("mAcc (%)", "macc", 100, 2);
  row("OA (%)", "oacc", 100, 2);
  row("PSNR (dB)", "psnr", 1, 2);
  row("PSNR on covered pixels (dB)", "psnr_covered", 1, 2);
  row("covered pixels (%)", "covered_fraction", 100, 1);
  row("SSIM", "ssim", 1, 4);
  row("Gaussians", "num_gaussians", 1, 0);
  row("iterations", "iterations", 1, 0);
  row("training time (s)", "train_seconds", 1, 1);
  if (run.metrics.is_null()) {
    md << "\nNo metrics.json in " << run.dir << ": run `sadsplat eval " << run.dir
       << "` first for the metrics, the IoU per class and the panels.\n";
  }
  md << "\n## Loss\n\n![loss](loss.png)\n\n## Gaussians\n\n![Gaussians](gaussians.png)\n\n";
  for (const auto& r : run.log) {
    if (r.type != "max_gaussians_reached") continue;
    md << "**The model reached max_gaussians at iteration " << r.iteration << " (" << r.gaussians
       << " Gaussians); densification added no more.** " << io::kMaxGaussiansAdvice << ".\n\n";
  }
  std::size_t events = 0;
  for (const auto& r : run.log) {
    if (r.type == "drop") {
      md << (events++ == 0 ? "| iteration | removed | left | low confidence | unseen | closed gate "
                             "|\n|---|---|---|---|---|---|\n"
                           : "")
         << "| " << r.iteration << " | " << r.removed << " | " << r.gaussians << " | "
         << r.low_confidence << " | " << r.unseen << " | " << r.closed_gate << " |\n";
    } else if (r.type == "closed_gates") {
      md << (events++ == 0 ? "| iteration | removed | left | low confidence | unseen | closed gate "
                             "|\n|---|---|---|---|---|---|\n"
                           : "")
         << "| " << r.iteration << " (end) | " << r.removed << " | " << r.gaussians << " | - | - | "
         << r.removed << " |\n";
    } else if (r.type == "recovery") {
      md << (events++ == 0 ? "| iteration | removed | left | low confidence | unseen | closed gate "
                             "|\n|---|---|---|---|---|---|\n"
                           : "")
         << "| " << r.iteration << " (recovery: gates folded, " << r.removed - r.closed_gate
         << " least contributing pruned) | " << r.removed << " | " << r.gaussians << " | - | - | "
         << r.closed_gate << " |\n";
    }
  }
  if (events == 0) md << "No drop events (a run without the semantic-aware drop).\n";
  if (have_iou) md << "\n## IoU per class\n\n![IoU per class](per_class_iou.png)\n";
  const fs::path panels = io::RunDirectory(run.dir).panels();
  if (io::isDirectory(panels.string())) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(panels)) {
      if (e.path().extension() == ".png") names.push_back(e.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    if (!names.empty()) {
      md << "\n## Test views\n\nimage | render | ground truth | prediction | error\n\n";
      const fs::path rel = fs::relative(panels, fs::absolute(out));
      for (const auto& n : names) {
        md << "![" << n << "](" << (rel / n).generic_string() << ")\n\n";
      }
    }
  }
  const std::string report = file("report.md");
  io::writeFileAtomically(report, [&](std::ostream& o) { o << md.str(); });
  return report;
}

}  // namespace viz
}  // namespace sadsplat
