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
#include "sadsplat/eval/metrics.h"
#include "sadsplat/geo/raster_files.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/pipeline/ortho_render.h"
#include "sadsplat/pipeline/runs.h"
#include "sadsplat/synth/aerial_benchmark.h"

namespace sadsplat {
namespace pipeline {
namespace {

using Vec3 = std::array<double, 3>;
const std::vector<std::string> kRenderOutputs{"class", "colour", "rgb", "depth", "confidence"};

std::string stemOf(const std::string& name) {
  std::string s = name;
  const std::size_t dot = s.find_last_of('.');
  if (dot != std::string::npos && s.find('/', dot) == std::string::npos) s.resize(dot);
  std::replace(s.begin(), s.end(), '/', '_');
  return s;
}

void writeTextFile(const std::string& path, const std::string& text) {
  io::writeFileAtomically(path, [&](std::ostream& out) { out << text; });
}

// The directory a scene was imported from (original photos in its images/), or "".
std::string sceneDirectory(const OpenedRun& run) {
  if (io::isDirectory(run.scene_path)) return run.scene_path;
  const std::string& source = run.scene.source;
  if (source.empty()) return "";
  if (io::isDirectory(source)) return source;
  // A relative path is the one `import` was given, from the directory it ran in: usually an
  // ancestor of the cache's folder.
  if (source[0] != '/') {
    std::filesystem::path dir = std::filesystem::absolute(run.scene_path).parent_path();
    for (; !dir.empty() && dir != dir.root_path(); dir = dir.parent_path()) {
      if (io::isDirectory((dir / source).string())) return (dir / source).string();
    }
  }
  return "";
}

std::array<double, 9> lookAt(const Vec3& eye, const Vec3& target, const Vec3& up) {
  auto norm = [](Vec3 v) {
    const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    return Vec3{v[0] / n, v[1] / n, v[2] / n};
  };
  auto cross = [](const Vec3& a, const Vec3& b) {
    return Vec3{a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
  };
  const Vec3 f = norm({target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]});
  const Vec3 right = norm(cross(f, up));
  const Vec3 down = cross(f, right);
  return {right[0], right[1], right[2], down[0], down[1], down[2], f[0], f[1], f[2]};
}

struct NamedCamera {
  std::string name;
  gaussians::RasterCamera camera;
};

// N cameras on a circle around the model's centre, at the training cameras' mean height and
// distance, looking at the centre, with the intrinsics of the first training view.
std::vector<NamedCamera> orbitCameras(const OpenedRun& run, int n, const io::View& like) {
  const geo::MapFrame frame = geo::localMapFrame(geo::sceneUp(run.scene));
  const at::Tensor means = run.trainer->parameters().means.detach().to(at::kCPU, at::kDouble);
  const at::Tensor median = std::get<0>(means.median(0));
  const Vec3 centre{median[0].item<double>(), median[1].item<double>(), median[2].item<double>()};
  const Vec3 lc = frame.toLocal(centre);
  double radius = 0, height = 0;
  int count = 0;
  for (const io::View& v : run.scene.views) {
    const Vec3 c = frame.toLocal(gaussians::RasterCamera::fromPinhole(v.camera).centre());
    radius += std::hypot(c[0] - lc[0], c[1] - lc[1]);
    height += c[2] - lc[2];
    ++count;
  }
  radius = std::max(radius / count, 1e-3);
  height /= count;
  const auto& L = frame.scene_to_local;  // rows: east', north', up in scene coordinates
  const Vec3 up{L[6], L[7], L[8]};
  std::vector<NamedCamera> cams;
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    const double e = std::cos(a) * radius, no = std::sin(a) * radius;
    Vec3 eye;
    for (int j = 0; j < 3; ++j) eye[j] = centre[j] + e * L[j] + no * L[3 + j] + height * up[j];
    const auto R = lookAt(eye, centre, up);
    gaussians::RasterCamera cam = gaussians::RasterCamera::fromPinhole(like.camera);
    cam.setRotation(R);
    for (int r = 0; r < 3; ++r) {
      cam.tvec[r] = -(R[3 * r] * eye[0] + R[3 * r + 1] * eye[1] + R[3 * r + 2] * eye[2]);
    }
    std::ostringstream name;
    name << "orbit_" << std::setw(3) << std::setfill('0') << i;
    cams.push_back({name.str(), cam});
  }
  return cams;
}

void writeViewImages(const gaussians::Trainer& trainer, const std::vector<ClassInfo>& classes,
                     const gaussians::RasterCamera& cam, const std::string& name,
                     const std::string& out, const std::set<std::string>& outputs) {
  const gaussians::RenderResult r = trainer.renderCamera(cam);
  const int W = cam.width, H = cam.height;
  const std::size_t n = static_cast<std::size_t>(W) * H;
  const at::Tensor alpha = r.alpha.to(at::kCPU, at::kFloat).contiguous();
  const float* pa = alpha.data_ptr<float>();
  if (outputs.count("rgb")) {
    const at::Tensor rgb = r.rgb.clamp(0, 1).mul(255).round().to(at::kCPU, at::kByte).contiguous();
    geo::Raster img = geo::Raster::bytesOf(W, H, 3);
    std::copy(rgb.data_ptr<std::uint8_t>(), rgb.data_ptr<std::uint8_t>() + 3 * n,
              img.bytes.begin());
    geo::writePng(out + "/rgb/" + name + ".png", img);
  }
  if (outputs.count("depth")) {
    const at::Tensor depth = r.depth.to(at::kCPU, at::kFloat).contiguous();
    geo::Raster img = geo::Raster::floatsOf(W, H);
    const float* pd = depth.data_ptr<float>();
    for (std::size_t i = 0; i < n; ++i) img.floats[i] = pa[i] >= 0.5f ? pd[i] : 0.f;
    img.nodata = 0.0;
    geo::writeGeoTiff(out + "/depth/" + name + ".tif", img, nullptr);
  }
  const bool want_classes =
      outputs.count("class") || outputs.count("colour") || outputs.count("confidence");
  if (!want_classes || trainer.numClasses() == 0) return;
  const auto best = trainer.classCosines(r).max(2);
  const at::Tensor conf = std::get<0>(best).to(at::kCPU, at::kFloat).contiguous();
  const at::Tensor cls = std::get<1>(best).to(at::kCPU, at::kLong).contiguous();
  const float* pc = conf.data_ptr<float>();
  const std::int64_t* pk = cls.data_ptr<std::int64_t>();
  geo::Raster ids = geo::Raster::bytesOf(W, H, 1), colour = geo::Raster::bytesOf(W, H, 3),
              confidence = geo::Raster::bytesOf(W, H, 1);
  for (std::size_t i = 0; i < n; ++i) {
    if (pa[i] < 0.5f) {
      ids.bytes[i] = 255;
      continue;
    }
    ids.bytes[i] = static_cast<std::uint8_t>(pk[i]);
    for (int c = 0; c < 3; ++c) colour.bytes[3 * i + c] = classes[pk[i]].color[c];
    confidence.bytes[i] = static_cast<std::uint8_t>(std::lround(255.f * std::max(0.f, pc[i])));
  }
  if (outputs.count("class")) geo::writePng(out + "/class/" + name + ".png", ids);
  if (outputs.count("colour")) geo::writePng(out + "/colour/" + name + ".png", colour);
  if (outputs.count("confidence")) geo::writePng(out + "/confidence/" + name + ".png", confidence);
}

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

}  // namespace

int renderRun(const RenderRunOptions& o) {
  std::set<std::string> outputs;
  for (const std::string& x : o.outputs) {
    if (std::find(kRenderOutputs.begin(), kRenderOutputs.end(), x) == kRenderOutputs.end()) {
      throw Error("<render>", "--outputs", "some of class, colour, rgb, depth, confidence", x);
    }
    outputs.insert(x);
  }
  if ((o.width > 0) != (o.height > 0) || o.width < 0 || o.height < 0 || o.width > 16384 ||
      o.height > 16384) {
    throw Error("<render>", "--size", "WxH, each 1..16384",
                std::to_string(o.width) + "x" + std::to_string(o.height));
  }
  if (o.scale < 0 || o.scale > 8 || !std::isfinite(o.scale)) {
    throw Error("<render>", "--scale", "a factor in (0, 8] of the imported size",
                std::to_string(o.scale));
  }
  int orbit = 0;
  if (!o.path.empty()) {
    const std::string prefix = "orbit:";
    char* end = nullptr;
    const long v = o.path.compare(0, prefix.size(), prefix) == 0
                       ? std::strtol(o.path.c_str() + prefix.size(), &end, 10)
                       : 0;
    if (!end || *end != '\0' || v < 1 || v > 3600) {
      throw Error("<render>", "--path", "orbit:N with N in 1..3600", o.path);
    }
    orbit = static_cast<int>(v);
  }
  OpenedRun run = openRun(o.run);
  if (run.trainer->numClasses() == 0 &&
      (outputs.count("class") || outputs.count("colour") || outputs.count("confidence"))) {
    for (const char* x : {"class", "colour", "confidence"}) outputs.erase(x);
    if (o.progress) {
      *o.progress << "note: the model has no classes: no class, colour or confidence images\n";
    }
    if (outputs.empty()) {
      throw Error(o.run, "--outputs", "rgb or depth (the model has no classes)",
                  "class outputs only");
    }
  }
  std::vector<const io::View*> views;
  if (o.views == "all" || o.views == "train" || o.views == "test") {
    for (const io::View& v : run.scene.views) {
      if (o.views == "all" || (o.views == "train" && v.train) || (o.views == "test" && v.test)) {
        views.push_back(&v);
      }
    }
  } else {
    std::stringstream names(o.views);
    std::string name;
    while (std::getline(names, name, ',')) {
      const auto it =
          std::find_if(run.scene.views.begin(), run.scene.views.end(),
                       [&](const io::View& v) { return v.name == name || stemOf(v.name) == name; });
      if (it == run.scene.views.end()) {
        std::string some;
        for (std::size_t i = 0; i < std::min<std::size_t>(3, run.scene.views.size()); ++i) {
          some += (i ? ", " : "") + run.scene.views[i].name;
        }
        throw Error(run.scene_path, "--views",
                    "all, train, test or image names of the scene (" + some + ", ...)", name);
      }
      views.push_back(&*it);
    }
  }
  if (views.empty() && orbit == 0) {
    throw Error(run.scene_path, "--views", "a selection with at least one view", o.views);
  }
  io::makeDirectory(o.out);
  for (const std::string& x : outputs) io::makeDirectory(o.out + "/" + x);
  const std::string scene_dir = sceneDirectory(run);

  auto sized = [&](gaussians::RasterCamera cam, const std::string& image) {
    int W = cam.width, H = cam.height;
    if (o.width > 0) {
      W = o.width, H = o.height;
    } else if (o.scale > 0) {
      W = std::max(1, static_cast<int>(std::lround(cam.width * o.scale)));
      H = std::max(1, static_cast<int>(std::lround(cam.height * o.scale)));
    } else if (!scene_dir.empty() && !image.empty()) {
      if (const auto size = geo::imageFileSize(scene_dir + "/images/" + image)) {
        W = (*size)[0], H = (*size)[1];
      }
    }
    const double sx = double(W) / cam.width, sy = double(H) / cam.height;
    cam.fx *= sx, cam.cx *= sx, cam.fy *= sy, cam.cy *= sy;
    cam.width = W, cam.height = H;
    return cam;
  };

  std::vector<NamedCamera> cameras;
  if (orbit > 0) {
    const io::View* like = views.empty() ? &run.scene.views.front() : views.front();
    for (NamedCamera& c : orbitCameras(run, orbit, *like)) {
      cameras.push_back({c.name, sized(c.camera, like->name)});
    }
  } else {
    for (const io::View* v : views) {
      cameras.push_back(
          {stemOf(v->name), sized(gaussians::RasterCamera::fromPinhole(v->camera), v->name)});
    }
  }
  int written = 0;
  for (std::size_t i = 0; i < cameras.size(); ++i) {
    if (o.progress) {
      *o.progress << "\rrender " << i + 1 << "/" << cameras.size() << " " << cameras[i].name << " ("
                  << cameras[i].camera.width << "x" << cameras[i].camera.height << ")   "
                  << std::flush;
    }
    writeViewImages(*run.trainer, run.scene.classes, cameras[i].camera, cameras[i].name, o.out,
                    outputs);
    ++written;
  }
  if (o.progress) *o.progress << "\n";
  return written;
}

std::string orthoRun(const OrthoRunOptions& o) {
  if (o.gsd && !(*o.gsd > 0 && std::isfinite(*o.gsd))) {
    throw Error("<ortho>", "--gsd", "a ground sample distance > 0 (metres per pixel)",
                std::to_string(*o.gsd));
  }
  if (!geo::haveGdal()) {
    throw Error("<ortho>", "build", "a sadsplat build with GDAL (Debian: libgdal-dev)",
                "a build without it");
  }
  io::makeDirectory(o.out);  // an unwritable output fails before the work
  OpenedRun run = openRun(o.run);
  const double gsd = o.gsd ? *o.gsd : roundToSignificant(photoGsd(run), 2);
  const OrthoGrid grid = footprintGrid(*run.trainer, run.scene, gsd, o.bounds);
  if (o.progress) {
    *o.progress << "ortho: " << grid.width << " x " << grid.height << " pixels at " << gsd << " m, "
                << grid.frame.crs_name << "\n";
  }
  const OrthoImages img = renderOrtho(*run.trainer, grid, o.progress);
  const std::size_t n = static_cast<std::size_t>(img.width) * img.height;
  geo::MapGrid map{grid.x0, grid.y0, grid.gsd, grid.frame.wkt};

  geo::Raster photo = geo::Raster::bytesOf(img.width, img.height, 4);
  photo.last_band_is_alpha = true;
  for (std::size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) photo.bytes[4 * i + c] = img.rgb[3 * i + c];
    photo.bytes[4 * i + 3] = img.covered[i] ? 255 : 0;
  }
  geo::writeGeoTiff(o.out + "/orthophoto.tif", photo, &map);
  geo::writePng(o.out + "/orthophoto.png", photo);

  const auto& classes = run.scene.classes;
  const bool semantic = run.trainer->numClasses() > 0;
  std::vector<std::int64_t> pixels(classes.size(), 0);
  std::int64_t covered = 0;
  for (std::size_t i = 0; i < n; ++i) {
    covered += img.covered[i];
    if (img.classes[i] < classes.size()) ++pixels[img.classes[i]];
  }
  if (semantic) {
    geo::Raster ids = geo::Raster::bytesOf(img.width, img.height, 1);
    ids.bytes = img.classes;
    ids.nodata = 255;
    for (const ClassInfo& c : classes) ids.palette.push_back(c.color);
    geo::writeGeoTiff(o.out + "/classes.tif", ids, &map);
    geo::Raster preview = geo::Raster::bytesOf(img.width, img.height, 4);
    preview.last_band_is_alpha = true;
    for (std::size_t i = 0; i < n; ++i) {
      if (img.classes[i] >= classes.size()) continue;
      for (int c = 0; c < 3; ++c) preview.bytes[4 * i + c] = classes[img.classes[i]].color[c];
      preview.bytes[4 * i + 3] = 255;
    }
    geo::writePng(o.out + "/classes.png", preview);
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
    geo::writeGeoTiff(o.out + "/confidence.tif", conf, &map);
    geo::writePng(o.out + "/confidence.png", conf_preview);
  }
  geo::Raster dsm = geo::Raster::floatsOf(img.width, img.height);
  dsm.nodata = -9999;
  std::vector<float> heights;
  for (std::size_t i = 0; i < n; ++i) {
    dsm.floats[i] = img.covered[i] ? img.elevation[i] : -9999.f;
    if (img.covered[i]) heights.push_back(img.elevation[i]);
  }
  geo::writeGeoTiff(o.out + "/dsm.tif", dsm, &map);
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
  geo::writePng(o.out + "/dsm.png", dsm_preview);

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
  writeTextFile(o.out + "/classes.csv", csv.str());

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
  j["map_scale_factor"] = grid.frame.k;
  j["grid_convergence_degrees"] = std::atan2(grid.frame.s, grid.frame.c) * 180 / M_PI;
  j["similarity_fit_residual_m"] = grid.frame.fit_residual;
  j["height_datum"] = grid.frame.georeferenced
                          ? "the photos' GPS altitude reference (origin altitude + local up)"
                          : "the scene frame's up axis";
  j["files"] = semantic ? nlohmann::json{"orthophoto.tif", "classes.tif", "dsm.tif",
                                         "confidence.tif", "classes.csv"}
                        : nlohmann::json{"orthophoto.tif", "dsm.tif", "classes.csv"};
  writeTextFile(o.out + "/ortho.json", j.dump(2) + "\n");

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
  return s.str();
}

std::string evalOrthoRun(const std::string& run_dir, const std::string& truth_json_in) {
  OpenedRun run = openRun(run_dir);
  if (run.trainer->numClasses() == 0) {
    throw Error(run_dir, "model", "a semantic model (classes) to score on the map", "no classes");
  }
  std::string truth_json = truth_json_in;
  if (truth_json.empty()) {
    const std::string dir = sceneDirectory(run);
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
  grid.top = orthoTop(*run.trainer, grid.frame);
  const OrthoImages img = renderOrtho(*run.trainer, grid);
  const int C = run.trainer->numClasses();
  eval::ConfusionMatrix confusion(C);
  std::vector<std::uint8_t> gt;
  std::vector<std::int64_t> pred;
  std::int64_t labelled = 0, uncovered = 0;
  std::vector<std::int64_t> truth_cells(C, 0), predicted_cells(C, 0);
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
    gt.push_back(g);
    pred.push_back(img.classes[i]);
  }
  confusion.add(gt.data(), pred.data(), gt.size());
  const auto iou = confusion.perClassIou();
  nlohmann::json j;
  j["truth"] = truth_source;
  j["gsd"] = grid.gsd;
  j["cells"] = labelled;
  j["uncovered_share"] = labelled ? double(uncovered) / labelled : 0.0;
  j["miou"] = confusion.meanIou();
  j["oacc"] = confusion.overallAccuracy();
  nlohmann::json per_class = nlohmann::json::object(), area = nlohmann::json::object();
  const double cell_area = grid.gsd * grid.gsd;
  for (int c = 0; c < C; ++c) {
    const std::string& name = run.scene.classes[c].name;
    per_class[name] = iou[c] < 0 ? nlohmann::json(nullptr) : nlohmann::json(iou[c]);
    nlohmann::json a;
    a["truth_m2"] = truth_cells[c] * cell_area;
    a["predicted_m2"] = predicted_cells[c] * cell_area;
    a["relative_error"] = nullptr;
    if (truth_cells[c] > 0) {
      a["relative_error"] = double(predicted_cells[c] - truth_cells[c]) / truth_cells[c];
    }
    area[name] = a;
  }
  j["per_class_iou"] = per_class;
  j["area"] = area;
  const std::string text = j.dump(2) + "\n";
  writeTextFile(run_dir + "/ortho_metrics.json", text);
  return text;
}

}  // namespace pipeline
}  // namespace sadsplat
