#include "sadsplat/eval/experiment_table.h"

#include <dirent.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <set>
#include <sstream>
#include <tuple>
#include <utility>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/run_directory.h"

namespace sadsplat {
namespace eval {
namespace {

std::vector<std::string> subdirectories(const std::string& dir) {
  std::vector<std::string> names;
  DIR* d = ::opendir(dir.c_str());
  if (d == nullptr)
    throw Error(dir, "folder", "a readable experiment results folder", std::strerror(errno));
  while (const dirent* e = ::readdir(d)) {
    const std::string name = e->d_name;
    if (name != "." && name != ".." && io::isDirectory(dir + "/" + name)) names.push_back(name);
  }
  ::closedir(d);
  std::sort(names.begin(), names.end());
  return names;
}

double number(const nlohmann::json& j, const char* key, const std::string& file) {
  if (!j.contains(key) || !j[key].is_number())
    throw Error(file, key, "a number",
                j.contains(key) ? j[key].dump().substr(0, 40) : std::string("missing"));
  return j[key].get<double>();
}

std::string formatMeanStd(const MeanStd& m, int precision, double scale = 1) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(precision) << m.mean * scale << " ± " << m.std * scale;
  return s.str();
}

// The rows of one group of runs (a scene or a kind), one per configuration.
void writeRows(std::ostringstream& out, const std::vector<const ExperimentRun*>& group,
               const std::vector<std::string>& configs, const std::string& baseline,
               const std::string& label) {
  double baseline_gaussians = 0;
  for (const std::string& config : configs) {
    std::vector<double> miou, psnr, ssim, gaussians, floaters;
    for (const ExperimentRun* r : group) {
      if (r->config != config) continue;
      miou.push_back(r->miou);
      psnr.push_back(r->psnr);
      ssim.push_back(r->ssim);
      gaussians.push_back(r->gaussians);
      if (r->large_floaters >= 0) floaters.push_back(r->large_floaters);
    }
    if (miou.empty()) continue;
    const MeanStd g = meanStd(gaussians);
    if (config == baseline) baseline_gaussians = g.mean;
    std::ostringstream fewer;
    if (baseline_gaussians > 0 && g.mean > 0) {
      fewer << std::fixed << std::setprecision(1) << baseline_gaussians / g.mean << "×";
    } else {
      fewer << "–";
    }
    out << "| " << label << " | " << config << " | " << miou.size() << " | "
        << formatMeanStd(meanStd(miou), 2, 100) << " | " << formatMeanStd(meanStd(psnr), 2) << " | "
        << formatMeanStd(meanStd(ssim), 3) << " | " << formatMeanStd(g, 0) << " | " << fewer.str()
        << " | " << (floaters.empty() ? std::string("–") : formatMeanStd(meanStd(floaters), 0))
        << " |\n";
  }
}

}  // namespace

MeanStd meanStd(const std::vector<double>& values) {
  MeanStd m;
  m.n = static_cast<int>(values.size());
  if (values.empty()) return m;
  for (double v : values) m.mean += v / m.n;
  if (m.n > 1) {
    double sum = 0;
    for (double v : values) sum += (v - m.mean) * (v - m.mean);
    m.std = std::sqrt(sum / (m.n - 1));
  }
  return m;
}

std::vector<ExperimentRun> readExperimentRuns(const std::string& results_dir) {
  std::vector<ExperimentRun> runs;
  for (const std::string& scene : subdirectories(results_dir)) {
    const std::size_t kind_end = scene.find_last_of('_');
    if (kind_end == std::string::npos || kind_end == 0) {
      throw Error(results_dir + "/" + scene, "folder name", "<kind>_<scene seed>, e.g. city_0",
                  scene);
    }
    for (const std::string& run : subdirectories(results_dir + "/" + scene)) {
      const std::string file = io::RunDirectory(results_dir + "/" + scene + "/" + run).metrics();
      if (!io::isRegularFile(file)) continue;
      const std::size_t seed_at = run.rfind("_t");
      char* end = nullptr;
      const long seed =
          seed_at == std::string::npos ? -1 : std::strtol(run.c_str() + seed_at + 2, &end, 10);
      if (seed < 0 || seed_at == 0 || end == nullptr || *end != '\0') {
        throw Error(results_dir + "/" + scene + "/" + run, "folder name",
                    "<configuration>_t<training seed>, e.g. full_t0", run);
      }
      nlohmann::json j;
      try {
        j = nlohmann::json::parse(io::readWholeFile(file));
      } catch (const nlohmann::json::exception& e) {
        throw Error(file, "JSON", "metrics written by sadsplat eval", e.what());
      }
      ExperimentRun r;
      r.scene = scene;
      r.kind = scene.substr(0, kind_end);
      r.config = run.substr(0, seed_at);
      r.training_seed = static_cast<int>(seed);
      r.miou = number(j, "miou", file);
      r.psnr = number(j, "psnr", file);
      r.ssim = number(j, "ssim", file);
      r.gaussians = number(j, "num_gaussians", file);
      r.large_floaters = -1;
      if (j.contains("floaters") && j["floaters"].is_object()) {
        r.large_floaters = number(j["floaters"], "larger_than_10pct_extent", file);
      }
      if (j.contains("per_class_iou") && j["per_class_iou"].is_object()) {
        for (auto it = j["per_class_iou"].begin(); it != j["per_class_iou"].end(); ++it) {
          if (it.value().is_number()) r.class_iou[it.key()] = it.value().get<double>();
        }
      }
      runs.push_back(r);
    }
  }
  std::sort(runs.begin(), runs.end(), [](const ExperimentRun& a, const ExperimentRun& b) {
    return std::tie(a.scene, a.config, a.training_seed) <
           std::tie(b.scene, b.config, b.training_seed);
  });
  return runs;
}

std::string experimentTables(const std::vector<ExperimentRun>& runs, const std::string& baseline) {
  // Configurations: the baseline first, then by name; scenes and kinds by name.
  std::set<std::string> config_set, scene_set, kind_set;
  for (const ExperimentRun& r : runs) {
    config_set.insert(r.config);
    scene_set.insert(r.scene);
    kind_set.insert(r.kind);
  }
  std::vector<std::string> configs;
  if (config_set.count(baseline)) configs.push_back(baseline);
  for (const std::string& c : config_set) {
    if (c != baseline) configs.push_back(c);
  }
  const std::string header =
      "| %s | configuration | runs | mIoU % | PSNR dB | SSIM | Gaussians | fewer than " + baseline +
      " | Gaussians > 10 % of the extent |\n|---|---|---|---|---|---|---|---|---|\n";
  const auto table_header = [&](const std::string& what) {
    std::string h = header;
    h.replace(h.find("%s"), 2, what);
    return h;
  };
  std::ostringstream out;
  out << "## Per scene (mean ± std over training seeds)\n\n" << table_header("scene");
  for (const std::string& scene : scene_set) {
    std::vector<const ExperimentRun*> group;
    for (const ExperimentRun& r : runs) {
      if (r.scene == scene) group.push_back(&r);
    }
    writeRows(out, group, configs, baseline, scene);
  }
  out << "\n## Per scene kind (mean ± std over scenes and training seeds)\n\n"
      << table_header("kind");
  for (const std::string& kind : kind_set) {
    std::vector<const ExperimentRun*> group;
    for (const ExperimentRun& r : runs) {
      if (r.kind == kind) group.push_back(&r);
    }
    writeRows(out, group, configs, baseline, kind);
  }
  for (const std::string& kind : kind_set) {
    std::set<std::string> classes;
    for (const ExperimentRun& r : runs) {
      if (r.kind != kind) continue;
      for (const auto& c : r.class_iou) classes.insert(c.first);
    }
    out << "\n## Per-class IoU %, " << kind << " (mean over scenes and training seeds)\n\n"
        << "| configuration |";
    for (const std::string& c : classes) out << " " << c << " |";
    out << "\n|---|";
    for (std::size_t k = 0; k < classes.size(); ++k) out << "---|";
    out << "\n";
    for (const std::string& config : configs) {
      bool any = false;
      std::ostringstream row;
      row << "| " << config << " |";
      for (const std::string& c : classes) {
        std::vector<double> values;
        for (const ExperimentRun& r : runs) {
          const auto it = r.class_iou.find(c);
          if (r.kind == kind && r.config == config && it != r.class_iou.end()) {
            values.push_back(it->second);
          }
        }
        any = any || !values.empty();
        std::ostringstream cell;
        cell << std::fixed << std::setprecision(1) << 100 * meanStd(values).mean;
        row << " " << (values.empty() ? std::string("–") : cell.str()) << " |";
      }
      if (any) out << row.str() << "\n";
    }
  }
  return out.str();
}

std::vector<FrontierPoint> frontierPoints(const std::vector<ExperimentRun>& runs,
                                          const std::string& baseline) {
  struct Sums {
    std::vector<double> miou, psnr, gaussians;
  };
  std::map<std::pair<std::string, std::string>, Sums> groups;  // (scene, config)
  for (const ExperimentRun& r : runs) {
    Sums& s = groups[{r.scene, r.config}];
    s.miou.push_back(r.miou);
    s.psnr.push_back(r.psnr);
    s.gaussians.push_back(r.gaussians);
  }
  std::vector<FrontierPoint> points;
  for (const auto& [key, sums] : groups) {
    const auto base = groups.find({key.first, baseline});
    if (base == groups.end()) continue;
    const double gaussians = meanStd(sums.gaussians).mean;
    FrontierPoint p;
    p.scene = key.first;
    p.config = key.second;
    p.runs = static_cast<int>(sums.miou.size());
    p.fewer = gaussians > 0 ? meanStd(base->second.gaussians).mean / gaussians : 0;
    p.miou_change = 100 * (meanStd(sums.miou).mean - meanStd(base->second.miou).mean);
    p.psnr_change = meanStd(sums.psnr).mean - meanStd(base->second.psnr).mean;
    points.push_back(p);
  }
  return points;
}

}  // namespace eval
}  // namespace sadsplat
