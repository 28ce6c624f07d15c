// `sadsplat render`: what the model sees in every photo, or along an orbit.
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
#include "sadsplat/geo/raster_files.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/output_set.h"
#include "sadsplat/pipeline/opened_run.h"
#include "sadsplat/pipeline/ortho_render.h"

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
  // Written as a set: a failure leaves the previous renders whole, a rerun replaces them.
  io::OutputSet files(o.out, kRenderOutputs);
  for (const std::string& x : outputs) io::makeDirectory(files.path(x));
  const std::string scene_dir = sceneDirectoryOf(run);

  auto sized = [&](gaussians::RasterCamera cam, const std::string& image) {
    int W = cam.width, H = cam.height;
    if (o.width > 0) {
      W = o.width, H = o.height;
    } else if (o.scale > 0) {
      W = std::max(1, static_cast<int>(std::lround(cam.width * o.scale)));
      H = std::max(1, static_cast<int>(std::lround(cam.height * o.scale)));
    } else if (!scene_dir.empty() && !image.empty()) {
      // COLMAP scenes keep their photos in images/; transforms.json names them from its folder.
      for (const std::string& folder : {scene_dir + "/images/", scene_dir + "/"}) {
        if (const auto size = geo::imageFileSize(folder + image)) {
          W = (*size)[0], H = (*size)[1];
          break;
        }
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
    writeViewImages(*run.trainer, run.scene.classes, cameras[i].camera, cameras[i].name,
                    files.staging(), outputs);
    ++written;
  }
  files.commit();
  if (o.progress) *o.progress << "\n";
  return written;
}

}  // namespace pipeline
}  // namespace sadsplat
