// `sadsplat ortho` and `sadsplat eval --ortho`: the model on a map grid.
#include "sadsplat/pipeline/map_products.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/common/order_statistics.h"
#include "sadsplat/eval/dsm_scores.h"
#include "sadsplat/eval/metrics.h"
#include "sadsplat/eval/object_scores.h"
#include "sadsplat/geo/ground_model.h"
#include "sadsplat/geo/map_objects.h"
#include "sadsplat/geo/raster_files.h"
#include "sadsplat/geo/vector_files.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/output_set.h"
#include "sadsplat/pipeline/opened_run.h"
#include "sadsplat/pipeline/ortho_render.h"
#include "sadsplat/synth/aerial_benchmark.h"
#include "truth_world.h"

namespace sadsplat {
namespace pipeline {
namespace {

using Vec3 = std::array<double, 3>;

// Median over the training views of (camera height above the model's median ground) / focal
// length: the photos' ground sample distance at the imported resolution, in scene units.
double photoGsd(const OpenedRun& run) {
  const geo::MapFrame frame = geo::localMapFrame(geo::sceneUp(run.scene));
  const gaussians::GaussianParams g = run.trainer->parameters();
  const at::Tensor means = g.means.detach().to(at::kCPU, at::kDouble);
  const auto& L = frame.scene_to_local;
  const at::Tensor up = means.matmul(at::tensor({L[6], L[7], L[8]}, means.options()));
  const double ground = std::get<0>(up.median(0)).item<double>();
  std::vector<double> gsd;
  for (const io::View& v : run.scene.views) {
    if (!v.train) continue;
    const Vec3 c = frame.toLocal(gaussians::RasterCamera::fromPinhole(v.camera).centre());
    if (c[2] > ground) gsd.push_back((c[2] - ground) / v.camera.fx);
  }
  if (gsd.empty()) {
    throw Error("<ortho>", "--gsd",
                "a ground sample distance (no training camera is above the "
                "model's ground to take it from)",
                "none given");
  }
  std::nth_element(gsd.begin(), gsd.begin() + gsd.size() / 2, gsd.end());
  return gsd[gsd.size() / 2];
}

double roundToSignificant(double v, int digits) {
  const double p = std::pow(10.0, digits - 1 - std::floor(std::log10(v)));
  return std::round(v * p) / p;
}

// The render options `ortho` and `eval --ortho` share, checked before any file is read (errors
// name `what`, the command, and the flag); the cameras come with the scene.
OrthoRenderOptions checkedRenderOptions(const OrthoRunOptions& o, const char* what) {
  OrthoRenderOptions r;
  r.height = parseOrthoSurface(o.height, "--height");
  r.classes = parseOrthoSurface(o.class_from, "--class-from");
  if (o.min_views < 0) {
    throw Error(what, "--min-views", "a number of photos >= 0", std::to_string(o.min_views));
  }
  if (!(o.min_spread >= 0 && o.min_spread <= 360)) {
    throw Error(what, "--min-spread", "degrees in [0, 360]", std::to_string(o.min_spread));
  }
  if (!(o.depth_tolerance > 0 && o.depth_tolerance <= 1)) {
    throw Error(what, "--depth-tolerance", "a share of the depth in (0, 1]",
                std::to_string(o.depth_tolerance));
  }
  if (!(o.on_surface >= 0 && std::isfinite(o.on_surface))) {
    throw Error(what, "--on-surface", "a distance >= 0 in scene units (0: off)",
                std::to_string(o.on_surface));
  }
  if (!(o.raised_check >= 0 && o.raised_check <= 1)) {
    throw Error(what, "--raised-check", "a share of the raised class's height in [0, 1] (0: off)",
                std::to_string(o.raised_check));
  }
  if (!(o.pit_depth >= 0 && std::isfinite(o.pit_depth))) {
    throw Error(what, "--pit-depth", "a depth >= 0 in map units (0: off)",
                std::to_string(o.pit_depth));
  }
  if (!(o.object_step >= 0 && std::isfinite(o.object_step))) {
    throw Error(what, "--object-step", "a height step >= 0 in map units (0: plain regions)",
                std::to_string(o.object_step));
  }
  if (!(o.ground_window > 0 && std::isfinite(o.ground_window))) {
    throw Error(what, "--ground-window", "a window side > 0 in map units",
                std::to_string(o.ground_window));
  }
  r.raised_share = o.raised_check;
  r.pit_depth = o.pit_depth;
  r.ground_window = o.ground_window;
  r.min_views = o.min_views;
  r.min_spread_degrees = o.min_spread;
  r.max_surface_gap = o.on_surface;
  r.depth_tolerance = o.depth_tolerance;
  return r;
}

// What the raised-class check did (OrthoRenderOptions::raised_share), for ortho.json and
// ortho_metrics.json.
void addRaisedCheck(nlohmann::json& j, const OrthoRunOptions& o, const OrthoImages& img,
                    const std::vector<ClassInfo>& classes) {
  j["raised_check"] = o.raised_check;
  j["pit_depth"] = o.pit_depth;
  if (o.raised_check <= 0 && o.pit_depth <= 0) return;
  j["ground_window"] = o.ground_window;
  nlohmann::json heights = nlohmann::json::object(), raised = nlohmann::json::array();
  for (std::size_t c = 0; c < img.class_height_above_ground.size() && c < classes.size(); ++c) {
    const double h = img.class_height_above_ground[c];
    heights[classes[c].name] = std::isfinite(h) ? nlohmann::json(h) : nlohmann::json(nullptr);
  }
  for (int c : img.raised_classes) raised.push_back(classes.at(c).name);
  j["class_height_above_ground"] = heights;
  j["raised_classes"] = raised;
  const std::size_t n = img.classes.size();
  j["raised_lowered_share"] = n ? double(img.lowered_cells) / n : 0.0;
  j["pit_filled_share"] = n ? double(img.filled_pits) / n : 0.0;
  j["near_ground_share"] = img.near_ground;
  j["raised_check_applied"] = o.raised_check > 0 && img.near_ground >= geo::kMinNearGround;
  j["pit_depth_applied"] = o.pit_depth > 0 && img.near_ground >= geo::kMinNearGround;
}

// Errors of object heights (predicted - true): how many, median and median absolute, RMSE.
nlohmann::json heightErrorsJson(std::vector<double> e) {
  nlohmann::json j = {{"objects", e.size()}};
  if (e.empty()) return j;
  double sq = 0;
  for (double v : e) sq += v * v;
  std::vector<double> a(e.size());
  std::transform(e.begin(), e.end(), a.begin(), [](double v) { return std::abs(v); });
  j["rmse"] = std::sqrt(sq / e.size());
  j["median_error"] = quantileInPlace(e, 0.5);
  j["median_abs_error"] = quantileInPlace(a, 0.5);
  return j;
}

// Map objects smaller than this merge into the neighbour of their class they border most (the
// slivers the height cut leaves along walls); also the smallest building the map scores.
constexpr double kMinObjectM2 = 20;

// The objects of each class in `wanted` on the map: its covered cells split where the surface
// model steps by more than `step` (geo::mapObjects), numbered across the classes, each with its
// class, the median height of its cells and, where the render has a ground model, their median
// height above it.
struct ClassObjects {
  std::vector<int> labels;
  std::vector<geo::MapObjectAttributes> objects;
};
ClassObjects classObjects(const OrthoImages& img, const std::vector<int>& wanted, double step,
                          std::size_t min_cells) {
  const std::size_t n = img.classes.size();
  ClassObjects out;
  out.labels.assign(n, 0);
  geo::MapObjectOptions options;
  options.max_step = step;
  options.min_cells = min_cells;
  for (const int c : wanted) {
    std::vector<std::uint8_t> mask(n, 0);
    for (std::size_t i = 0; i < n; ++i) mask[i] = img.covered[i] && img.classes[i] == c;
    const std::vector<int> labels =
        geo::mapObjects(mask, img.elevation, img.width, img.height, options);
    const int first = static_cast<int>(out.objects.size());
    int count = 0;
    for (const int l : labels) count = std::max(count, l);
    std::vector<std::vector<float>> heights(static_cast<std::size_t>(count));
    std::vector<std::vector<float>> above(static_cast<std::size_t>(count));
    for (std::size_t i = 0; i < n; ++i) {
      if (!labels[i]) continue;
      out.labels[i] = first + labels[i];
      const auto k = static_cast<std::size_t>(labels[i]) - 1;
      heights[k].push_back(img.elevation[i]);
      if (i < img.ground.size() && std::isfinite(img.ground[i])) {
        above[k].push_back(img.elevation[i] - img.ground[i]);
      }
    }
    for (std::size_t k = 0; k < heights.size(); ++k) {
      geo::MapObjectAttributes a;
      a.class_id = c;
      a.height = quantileInPlace(heights[k], 0.5);
      if (!above[k].empty()) a.height_above_ground = quantileInPlace(above[k], 0.5);
      out.objects.push_back(a);
    }
  }
  return out;
}

}  // namespace

std::string orthoRun(const OrthoRunOptions& o) {
  if (o.gsd && !(*o.gsd > 0 && std::isfinite(*o.gsd))) {
    throw Error("<ortho>", "--gsd", "a ground sample distance > 0 (metres per pixel)",
                std::to_string(*o.gsd));
  }
  OrthoRenderOptions render_options = checkedRenderOptions(o, "<ortho>");
  if (!geo::haveGdal()) {
    throw Error("<ortho>", "build", "a sadsplat build with GDAL (Debian: libgdal-dev)",
                "a build without it");
  }
  // Written as a set: a failure leaves the previous set whole, a rerun replaces all of it.
  std::vector<std::string> outputs = {
      "orthophoto.tif", "orthophoto.png", "classes.tif", "classes.png", "confidence.tif",
      "confidence.png", "dsm.tif",        "dsm.png",     "classes.csv", "ortho.json"};
  if (!o.vectors.empty()) outputs.push_back("vectors.gpkg");
  io::OutputSet files(o.out, outputs);
  OpenedRun run = openRun(o.run);
  // The classes of --vectors, checked before the render.
  std::vector<int> vector_classes;
  std::vector<std::string> names;
  for (const ClassInfo& c : run.scene.classes) names.push_back(c.name);
  if (!o.vectors.empty() && run.trainer->numClasses() == 0) {
    throw Error("<ortho>", "--vectors", "a semantic model (classes)", "no classes");
  }
  for (const std::string& name : o.vectors) {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) {
      std::string known;
      for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
      throw Error("<ortho>", "--vectors", "class names of the model (" + known + ")", name);
    }
    vector_classes.push_back(static_cast<int>(it - names.begin()));
  }
  const double gsd = o.gsd ? *o.gsd : roundToSignificant(photoGsd(run), 2);
  const OrthoGrid grid = footprintGrid(*run.trainer, run.scene, gsd, o.bounds);
  if (o.progress) {
    *o.progress << "ortho: " << grid.width << " x " << grid.height << " pixels at " << gsd << " m, "
                << grid.frame.crs_name << "\n";
  }
  render_options.cameras = trainingCameras(run.scene);
  const OrthoImages img = renderOrtho(*run.trainer, grid, render_options, o.progress);
  const std::size_t n = static_cast<std::size_t>(img.width) * img.height;
  geo::MapGrid map{grid.x0, grid.y0, grid.gsd, grid.frame.wkt};

  geo::Raster photo = geo::Raster::bytesOf(img.width, img.height, 4);
  photo.last_band_is_alpha = true;
  for (std::size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) photo.bytes[4 * i + c] = img.rgb[3 * i + c];
    photo.bytes[4 * i + 3] = img.covered[i] ? 255 : 0;
  }
  geo::writeGeoTiff(files.path("orthophoto.tif"), photo, &map);
  geo::writePng(files.path("orthophoto.png"), photo);

  const auto& classes = run.scene.classes;
  const bool semantic = run.trainer->numClasses() > 0;
  std::vector<std::int64_t> pixels(classes.size(), 0);
  std::int64_t covered = 0;
  for (std::size_t i = 0; i < n; ++i) {
    covered += img.covered[i];
    if (img.classes[i] < classes.size()) ++pixels[img.classes[i]];
  }
  std::size_t polygons = 0;
  if (semantic) {
    geo::Raster ids = geo::Raster::bytesOf(img.width, img.height, 1);
    ids.bytes = img.classes;
    ids.nodata = 255;
    for (const ClassInfo& c : classes) ids.palette.push_back(c.color);
    geo::writeGeoTiff(files.path("classes.tif"), ids, &map);
    if (!o.vectors.empty()) {
      geo::ObjectPolygonOptions v;
      v.simplify = grid.gsd;
      v.min_area = 4 * grid.gsd * grid.gsd;
      const auto min_cells = static_cast<std::size_t>(std::ceil(kMinObjectM2 / (gsd * gsd)));
      const ClassObjects objects = classObjects(img, vector_classes, o.object_step, min_cells);
      polygons = geo::writeObjectPolygons(files.path("vectors.gpkg"), objects.labels, img.width,
                                          img.height, objects.objects, map, names, v);
    }
    geo::Raster preview = geo::Raster::bytesOf(img.width, img.height, 4);
    preview.last_band_is_alpha = true;
    for (std::size_t i = 0; i < n; ++i) {
      if (img.classes[i] >= classes.size()) continue;
      for (int c = 0; c < 3; ++c) preview.bytes[4 * i + c] = classes[img.classes[i]].color[c];
      preview.bytes[4 * i + 3] = 255;
    }
    geo::writePng(files.path("classes.png"), preview);
    geo::Raster conf = geo::Raster::floatsOf(img.width, img.height);
    conf.nodata = -1;
    geo::Raster conf_preview = geo::Raster::bytesOf(img.width, img.height, 2);
    conf_preview.last_band_is_alpha = true;
    for (std::size_t i = 0; i < n; ++i) {
      conf.floats[i] = img.covered[i] ? img.confidence[i] : -1.f;
      conf_preview.bytes[2 * i] =
          static_cast<std::uint8_t>(std::lround(255 * std::max(0.f, img.confidence[i])));
      conf_preview.bytes[2 * i + 1] = img.covered[i] ? 255 : 0;
    }
    geo::writeGeoTiff(files.path("confidence.tif"), conf, &map);
    geo::writePng(files.path("confidence.png"), conf_preview);
  }
  geo::Raster dsm = geo::Raster::floatsOf(img.width, img.height);
  dsm.nodata = -9999;
  std::vector<float> heights;
  for (std::size_t i = 0; i < n; ++i) {
    dsm.floats[i] = img.covered[i] ? img.elevation[i] : -9999.f;
    if (img.covered[i]) heights.push_back(img.elevation[i]);
  }
  geo::writeGeoTiff(files.path("dsm.tif"), dsm, &map);
  float lo = 0, hi = 1;
  if (!heights.empty()) {
    std::sort(heights.begin(), heights.end());
    lo = heights[heights.size() * 2 / 100];
    hi = std::max(lo + 1e-3f, heights[heights.size() * 98 / 100]);
  }
  geo::Raster dsm_preview = geo::Raster::bytesOf(img.width, img.height, 2);
  dsm_preview.last_band_is_alpha = true;
  for (std::size_t i = 0; i < n; ++i) {
    const float t = std::min(1.f, std::max(0.f, (img.elevation[i] - lo) / (hi - lo)));
    dsm_preview.bytes[2 * i] = static_cast<std::uint8_t>(std::lround(255 * t));
    dsm_preview.bytes[2 * i + 1] = img.covered[i] ? 255 : 0;
  }
  geo::writePng(files.path("dsm.png"), dsm_preview);

  // Ground area of a pixel: (gsd / k)^2 (the map's scale factor k; 1 in local metres).
  const double cell_area = gsd * gsd * grid.frame.groundAreaPerMapArea();
  std::int64_t classified = 0;
  for (auto p : pixels) classified += p;
  std::ostringstream csv;
  csv << "class_id,name,pixels,area_m2,share\n" << std::fixed;
  for (std::size_t c = 0; c < classes.size() && semantic; ++c) {
    csv << c << "," << classes[c].name << "," << pixels[c] << "," << std::setprecision(2)
        << pixels[c] * cell_area << "," << std::setprecision(6)
        << (classified ? double(pixels[c]) / classified : 0.0) << "\n";
  }
  csv << "255,nodata," << (static_cast<std::int64_t>(n) - covered) << "," << std::setprecision(2)
      << (static_cast<std::int64_t>(n) - covered) * cell_area << ",\n";
  io::writeTextFileAtomically(files.path("classes.csv"), csv.str());

  nlohmann::json j;
  j["run"] = o.run;
  j["crs"] = grid.frame.crs_name;
  j["epsg"] = grid.frame.epsg;
  j["georeferenced"] = grid.frame.georeferenced;
  j["gsd"] = gsd;
  j["gsd_from_photos"] = !o.gsd.has_value();
  j["origin_top_left"] = {grid.x0, grid.y0};
  j["width"] = grid.width;
  j["height"] = grid.height;
  j["covered_share"] = n ? double(covered) / n : 0.0;
  j["height"] = o.height;
  j["class_from"] = o.class_from;
  j["min_views"] = o.min_views;
  j["min_spread_degrees"] = o.min_spread;
  j["depth_tolerance"] = o.depth_tolerance;
  j["on_surface_m"] = o.on_surface;
  j["few_views_share"] = n ? double(img.few_views) / n : 0.0;
  addRaisedCheck(j, o, img, run.scene.classes);
  j["map_scale_factor"] = grid.frame.k;
  j["grid_convergence_degrees"] = std::atan2(grid.frame.s, grid.frame.c) * 180 / M_PI;
  j["similarity_fit_residual_m"] = grid.frame.fit_residual;
  if (run.scene.georeference && !run.scene.georeference->up_source.empty()) {
    // The frame's accuracy statement, as sfm measured it (georeference.json).
    const io::Georeference& g = *run.scene.georeference;
    nlohmann::json a = {{"source", g.up_source},
                        {"horizontal_rms_m", g.horizontal_rms_metres},
                        {"vertical_rms_m", g.vertical_rms_metres},
                        {"doubts", g.doubts}};
    if (g.check_points > 0) {
      a["check_points"] = g.check_points;
      a["check_rmse_horizontal_m"] = g.check_rmse_horizontal;
      a["check_rmse_vertical_m"] = g.check_rmse_vertical;
    }
    j["georeference_accuracy"] = a;
  }
  j["height_datum"] = grid.frame.georeferenced
                          ? "the photos' GPS altitude reference (origin altitude + local up)"
                          : "the scene frame's up axis";
  if (!o.vectors.empty()) {
    j["vectors"] = {{"file", "vectors.gpkg"},
                    {"polygons", polygons},
                    {"object_step_m", o.object_step},
                    {"merged_under_m2", kMinObjectM2}};
  }
  j["files"] = semantic ? nlohmann::json{"orthophoto.tif", "classes.tif", "dsm.tif",
                                         "confidence.tif", "classes.csv"}
                        : nlohmann::json{"orthophoto.tif", "dsm.tif", "classes.csv"};
  io::writeTextFileAtomically(files.path("ortho.json"), j.dump(2) + "\n");
  files.commit();

  std::ostringstream s;
  s << "wrote " << o.out << ": " << grid.width << " x " << grid.height << " pixels, " << gsd
    << " m, " << grid.frame.crs_name << ", " << std::setprecision(1) << std::fixed
    << 100.0 * covered / std::max<std::size_t>(1, n) << " % covered\n";
  if (semantic) {
    for (std::size_t c = 0; c < classes.size(); ++c) {
      s << "  " << std::left << std::setw(16) << classes[c].name << std::right << std::setw(12)
        << std::setprecision(1) << pixels[c] * cell_area << " m2  " << std::setw(5)
        << 100.0 * pixels[c] / std::max<std::int64_t>(1, classified) << " %\n";
    }
  }
  if (!o.vectors.empty()) {
    s << "  vectors.gpkg: " << polygons << " polygons of ";
    for (std::size_t k = 0; k < o.vectors.size(); ++k) s << (k ? ", " : "") << o.vectors[k];
    s << std::setprecision(2) << std::defaultfloat;
    if (o.object_step > 0) {
      s << " (regions cut where the DSM steps by more than " << o.object_step << ")\n";
    } else {
      s << " (plain regions)\n";
    }
  }
  return s.str();
}

std::string evalOrthoRun(const std::string& run_dir, const std::string& truth_json_in,
                         const OrthoRunOptions& render, const std::string& scene_override) {
  OrthoRenderOptions render_options = checkedRenderOptions(render, "<eval>");
  OpenedRun run = openRun(run_dir, scene_override);
  if (run.trainer->numClasses() == 0) {
    throw Error(run_dir, "model", "a semantic model (classes) to score on the map", "no classes");
  }
  std::string truth_json = truth_json_in;
  if (truth_json.empty()) {
    const std::string dir = sceneDirectoryOf(run);
    truth_json = (dir.empty() ? run.scene_path : dir) + "/ortho_truth.json";
  }
  // The truth: the JSON + PNG `sadsplat synth --out` writes, or (a synth scene cache, which
  // names its world) traced again from the world.
  OrthoGrid grid;
  grid.frame = geo::localMapFrame({0, 0, 1});  // the truth is on the scene frame's x-y plane
  std::vector<std::uint8_t> truth;
  std::string truth_source = truth_json;
  const std::optional<synth::World> world = truth_json_in.empty() && !io::isRegularFile(truth_json)
                                                ? synth::worldFromId(run.scene.source)
                                                : std::nullopt;
  if (world) {
    synth::OrthoTruth t = synth::orthoTruth(*world);
    grid.gsd = t.gsd, grid.x0 = t.x0, grid.y0 = t.y0, grid.width = t.width, grid.height = t.height;
    truth = std::move(t.classes);
    truth_source = run.scene.source + " (traced)";
  } else {
    if (!io::isRegularFile(truth_json)) {
      throw Error(truth_json, "file",
                  "the map-grid ground truth (ortho_truth.json, written by `sadsplat synth`)",
                  "missing");
    }
    nlohmann::json t;
    try {
      t = nlohmann::json::parse(io::readWholeFile(truth_json));
    } catch (const nlohmann::json::exception& e) {
      throw Error(truth_json, "JSON", "valid JSON", e.what());
    }
    for (const char* key : {"gsd", "x0", "y0", "width", "height", "classes_png"}) {
      if (!t.contains(key)) throw Error(truth_json, key, "a value", "missing");
    }
    const std::size_t slash = truth_json.find_last_of('/');
    const std::string dir = slash == std::string::npos ? "." : truth_json.substr(0, slash);
    const geo::Raster png = geo::readByteRaster(dir + "/" + t["classes_png"].get<std::string>());
    grid.gsd = t["gsd"].get<double>();
    grid.x0 = t["x0"].get<double>();
    grid.y0 = t["y0"].get<double>();
    grid.width = t["width"].get<int>();
    grid.height = t["height"].get<int>();
    if (png.width != grid.width || png.height != grid.height) {
      throw Error(truth_json, "width/height", "the size of " + t["classes_png"].get<std::string>(),
                  std::to_string(grid.width) + "x" + std::to_string(grid.height));
    }
    truth = png.bytes;
  }
  // The true DSM (the height of that topmost surface) where the world is known: traced on the
  // same grid (a synth cache names its world; a synth directory's ortho_truth.json does).
  std::vector<float> true_heights;
  const std::optional<synth::World> dsm_world =
      world ? world : synth::worldFromId(worldIdInTruthFile(truth_json));
  if (dsm_world) {
    synth::OrthoTruth t = synth::orthoTruth(*dsm_world, grid.gsd);
    if (t.width == grid.width && t.height == grid.height && t.x0 == grid.x0 && t.y0 == grid.y0) {
      true_heights = std::move(t.heights);
    }
  }
  grid.top = orthoTop(*run.trainer, grid.frame);
  render_options.cameras = trainingCameras(run.scene);
  const OrthoImages img = renderOrtho(*run.trainer, grid, render_options);
  const int C = run.trainer->numClasses();
  eval::ConfusionMatrix confusion(C);
  std::vector<std::uint8_t> gt;
  std::vector<std::int64_t> pred;
  std::int64_t labelled = 0, uncovered = 0;
  std::vector<std::int64_t> truth_cells(C, 0), truth_covered(C, 0), predicted_cells(C, 0);
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const std::uint8_t g = truth[i];
    if (g >= C) continue;
    ++labelled;
    ++truth_cells[g];
    if (!img.covered[i]) {
      ++uncovered;
      continue;
    }
    ++predicted_cells[img.classes[i]];
    ++truth_covered[g];
    gt.push_back(g);
    pred.push_back(img.classes[i]);
  }
  confusion.add(gt.data(), pred.data(), gt.size());
  const auto iou = confusion.perClassIou();
  // The same score over the cells near the grid's centre (what an orbit looks at): within these
  // shares of the half of the grid's shorter side.
  nlohmann::json within = nlohmann::json::array();
  const double half = 0.5 * grid.gsd * std::min(grid.width, grid.height);
  for (const double share : {0.5, 0.7, 0.9}) {
    const double r = share * half;
    const eval::ConfusionMatrix near = eval::confusionWithin(
        truth, img.classes, img.covered, grid.width, grid.height, grid.gsd, r, C);
    within.push_back({{"radius_share", share}, {"radius_m", r}, {"miou", near.meanIou()}});
  }
  nlohmann::json j;
  j["truth"] = truth_source;
  j["gsd"] = grid.gsd;
  j["cells"] = labelled;
  j["height"] = render.height;
  j["class_from"] = render.class_from;
  j["min_views"] = render.min_views;
  j["min_spread_degrees"] = render.min_spread;
  j["depth_tolerance"] = render.depth_tolerance;
  j["on_surface_m"] = render.on_surface;
  addRaisedCheck(j, render, img, run.scene.classes);
  j["uncovered_share"] = labelled ? double(uncovered) / labelled : 0.0;
  j["miou"] = confusion.meanIou();
  j["oacc"] = confusion.overallAccuracy();
  j["miou_within"] = within;
  nlohmann::json per_class = nlohmann::json::object(), area = nlohmann::json::object();
  const double cell_area = grid.gsd * grid.gsd;
  for (int c = 0; c < C; ++c) {
    const std::string& name = run.scene.classes[c].name;
    per_class[name] = iou[c] < 0 ? nlohmann::json(nullptr) : nlohmann::json(iou[c]);
    nlohmann::json a;
    // The error where the map says something (its nodata cells are neither class), and
    // against the whole labelled area (nodata counting as missing).
    a["truth_m2"] = truth_cells[c] * cell_area;
    a["truth_covered_m2"] = truth_covered[c] * cell_area;
    a["predicted_m2"] = predicted_cells[c] * cell_area;
    a["relative_error"] = nullptr;
    a["relative_error_all"] = nullptr;
    if (truth_covered[c] > 0) {
      a["relative_error"] = double(predicted_cells[c] - truth_covered[c]) / truth_covered[c];
    }
    if (truth_cells[c] > 0) {
      a["relative_error_all"] = double(predicted_cells[c] - truth_cells[c]) / truth_cells[c];
    }
    area[name] = a;
  }
  j["per_class_iou"] = per_class;
  j["area"] = area;
  // DSM error (the rendered elevation against the true top surface's height) over covered cells
  // of the labelled area, all and per true class: roofs, ground, vegetation apart; also away
  // from the truth's height steps (walls), where a fraction of a cell costs metres.
  if (!true_heights.empty()) {
    eval::DsmScoreOptions dsm_options;
    const eval::DsmScores scores = eval::scoreDsm(img.elevation, true_heights, truth, img.covered,
                                                  grid.width, grid.height, C, dsm_options);
    const auto summary = [](const eval::HeightErrors& e) {
      nlohmann::json d;
      d["cells"] = e.cells;
      if (e.cells == 0) return d;
      d["rmse_m"] = e.rmse_m;
      d["median_abs_m"] = e.median_abs_m;
      d["nmad_m"] = e.nmad_m;
      d["off_step_cells"] = e.off_step_cells;
      d["off_step_rmse_m"] = e.off_step_cells ? nlohmann::json(e.off_step_rmse_m) : nullptr;
      return d;
    };
    nlohmann::json dsm = summary(scores.all);
    dsm["step_m"] = dsm_options.step_m;
    nlohmann::json dsm_class = nlohmann::json::object();
    for (int c = 0; c < C; ++c) dsm_class[run.scene.classes[c].name] = summary(scores.per_class[c]);
    dsm["per_class"] = dsm_class;
    j["dsm"] = dsm;
  }
  // Buildings as map objects: the building cells split where the DSM steps by more than
  // render.object_step (as `ortho --vectors` writes them; slivers under kMinObjectM2 merged, and
  // objects under it not counted) against the world's standing buildings rasterised on the
  // grid, matched at IoU >= 0.5; also for other steps (0: the plain 8-connected regions).
  int building = -1;
  for (int c = 0; c < C; ++c) building = run.scene.classes[c].name == "building" ? c : building;
  if (dsm_world && !true_heights.empty() && building >= 0) {
    const std::size_t n_cells = static_cast<std::size_t>(grid.width) * grid.height;
    std::vector<int> truth_objects(n_cells, 0);
    const auto footprints =
        synth::groundFootprints(*dsm_world, static_cast<std::uint8_t>(building));
    for (std::size_t f = 0; f < footprints.size(); ++f) {
      const synth::ObjectFootprint& b = footprints[f];
      const int i0 = std::max(0, static_cast<int>(std::ceil((b.x0 - grid.x0) / grid.gsd - 0.5)));
      const int i1 =
          std::min(grid.width - 1, static_cast<int>(std::floor((b.x1 - grid.x0) / grid.gsd - 0.5)));
      const int j0 = std::max(0, static_cast<int>(std::ceil((grid.y0 - b.y1) / grid.gsd - 0.5)));
      const int j1 = std::min(grid.height - 1,
                              static_cast<int>(std::floor((grid.y0 - b.y0) / grid.gsd - 0.5)));
      for (int jj = j0; jj <= j1; ++jj) {
        for (int ii = i0; ii <= i1; ++ii) {
          truth_objects[static_cast<std::size_t>(jj) * grid.width + ii] = static_cast<int>(f) + 1;
        }
      }
    }
    const auto min_cells = static_cast<std::size_t>(std::ceil(kMinObjectM2 / cell_area));
    const auto objectScores = [&](double step) {
      const ClassObjects objects = classObjects(img, {building}, step, min_cells);
      const eval::ObjectScores o =
          eval::scoreRasterObjects(objects.labels, truth_objects, min_cells);
      nlohmann::json scored = buildingObjectsJson(
          o, {{"min_area_m2", kMinObjectM2}, {"object_step_m", step}, {"match_iou", 0.5}});
      // The matched objects' heights (as `ortho --vectors` writes them) against the true
      // building's top: the world's ground is z = 0, so its top is also its height above ground.
      std::vector<double> dsm_errors, above_errors;
      for (const auto& [t, p] : o.matches) {
        const synth::ObjectFootprint& f =
            footprints[static_cast<std::size_t>(o.true_labels[t]) - 1];
        const double top = dsm_world->objects()[static_cast<std::size_t>(f.object)].hi[2];
        const geo::MapObjectAttributes& a =
            objects.objects[static_cast<std::size_t>(o.predicted_labels[p]) - 1];
        dsm_errors.push_back(a.height - top);
        if (std::isfinite(a.height_above_ground))
          above_errors.push_back(a.height_above_ground - top);
      }
      scored["height_m"] = heightErrorsJson(dsm_errors);
      scored["height_above_ground_m"] = heightErrorsJson(above_errors);
      return scored;
    };
    j["objects"] = objectScores(render.object_step);
    nlohmann::json by_step = nlohmann::json::array();
    for (const double step : {0.0, 3.0, 2.0, 1.5, 1.0, 0.5}) by_step.push_back(objectScores(step));
    j["objects_by_step"] = by_step;
  }
  const std::string text = j.dump(2) + "\n";
  io::writeTextFileAtomically(run_dir + "/ortho_metrics.json", text);
  return text;
}

}  // namespace pipeline
}  // namespace sadsplat
