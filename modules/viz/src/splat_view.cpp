#include "sadsplat/viz/splat_view.h"

#include <vtkActor.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkInteractorStyleTrackballCamera.h>
#include <vtkLegendBoxActor.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPlaneSource.h>
#include <vtkPointData.h>
#include <vtkPointGaussianMapper.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSmartPointer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTexture.h>
#include <vtkUnsignedCharArray.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/common/semantic_cloud.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/viz/display.h"
#include "window_png.h"

namespace sadsplat {
namespace viz {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Class ids to show, from names or ids; empty set = all.
std::set<std::uint32_t> selectedClasses(const ViewModel& m, const std::vector<std::string>& names) {
  std::set<std::uint32_t> ids;
  for (const std::string& name : names) {
    bool found = false;
    for (std::size_t c = 0; c < m.classes.size(); ++c) {
      if (m.classes[c].name == name) {
        ids.insert(static_cast<std::uint32_t>(c));
        found = true;
      }
    }
    if (!found && !name.empty() && name.find_first_not_of("0123456789") == std::string::npos &&
        name.size() < 10) {
      ids.insert(static_cast<std::uint32_t>(std::stoul(name)));
      found = true;
    }
    if (!found) {
      std::string known;
      for (const auto& c : m.classes) known += (known.empty() ? "" : ", ") + c.name;
      throw Error(
          m.name, "--class " + name,
          m.classes.empty() ? "a class id (no classes.json beside the model)" : "one of: " + known,
          name);
    }
  }
  return ids;
}

// The view-independent splat colour of a class (grey when unlabelled or outside the list).
std::array<std::uint8_t, 3> classColor(const ViewModel& m, std::uint32_t label) {
  if (label < m.classes.size()) return m.classes[label].color;
  if (label == kUnlabelled || m.classes.empty()) {
    return {kUnlabelledGrey, kUnlabelledGrey, kUnlabelledGrey};
  }
  return {255, 0, 255};  // a label beyond the class list: visible on purpose
}

// Scene frame for the aerial camera: the centre and extent of the bulk of the Gaussians (2nd to
// 98th percentile per axis, so that far floaters do not set the view) and the up direction
// (towards the mean camera centre when the scene has cameras, else the ground plane's normal,
// pointing to +z).
struct SceneFrame {
  Eigen::Vector3d centre{0, 0, 0};
  Eigen::Vector3d up{0, 0, 1};
  double extent = 1.0;
};

SceneFrame sceneFrame(const ViewModel& m) {
  SceneFrame f;
  const auto& g = m.gaussians;
  if (g.empty()) return f;
  Eigen::Vector3d lo, hi;
  for (int k = 0; k < 3; ++k) {
    std::vector<float> v;
    v.reserve(g.size());
    for (const auto& p : g) v.push_back(k == 0 ? p.x : k == 1 ? p.y : p.z);
    std::sort(v.begin(), v.end());
    lo[k] = v[v.size() * 2 / 100];
    hi[k] = v[std::min(v.size() - 1, v.size() * 98 / 100)];
  }
  f.centre = 0.5 * (lo + hi);
  f.extent = std::max(1e-3, (hi - lo).norm());
  if (!m.cameras.empty()) {
    Eigen::Vector3d mean(0, 0, 0);
    for (const auto& [name, cam] : m.cameras) {
      const auto r = cam.rotation();
      const Eigen::Matrix3d R =
          Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(r.data());
      const Eigen::Vector3d t(cam.tvec[0], cam.tvec[1], cam.tvec[2]);
      mean += -R.transpose() * t;
    }
    mean /= static_cast<double>(m.cameras.size());
    if ((mean - f.centre).norm() > 1e-9) {
      f.up = (mean - f.centre).normalized();
      return f;
    }
  }
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : g) {
    const Eigen::Vector3d d = Eigen::Vector3d(p.x, p.y, p.z) - f.centre;
    if ((d.array().abs() <= (hi - lo).array()).all()) cov += d * d.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  f.up = eig.eigenvectors().col(0);
  if (f.up.z() < 0) f.up = -f.up;
  return f;
}

// Subclasses the trackball style so that sadsplat's keys are not also VTK's defaults ('3' turns
// on stereo, 'w' wireframe, 's' surface, ...).
class KeyStyle : public vtkInteractorStyleTrackballCamera {
 public:
  static KeyStyle* New();
  vtkTypeMacro(KeyStyle, vtkInteractorStyleTrackballCamera);
  std::function<bool(char)> on_key;
  void OnChar() override {
    const char key = this->Interactor->GetKeyCode();
    if (on_key && on_key(key)) return;
    if (key == 'q' || key == 'e' || key == 'f') vtkInteractorStyleTrackballCamera::OnChar();
  }
};
vtkStandardNewMacro(KeyStyle);

class SplatScene {
 public:
  SplatScene(const std::vector<ViewModel>& models, const SplatViewOptions& options)
      : models_(models), options_(options) {
    hidden_.resize(models_.size());
    for (std::size_t i = 0; i < models_.size(); ++i) {
      const auto shown = selectedClasses(models_[i], options_.classes);
      if (!shown.empty()) {
        for (std::uint32_t c = 0; c < std::max<std::size_t>(models_[i].classes.size(), 1); ++c) {
          if (!shown.count(c)) hidden_[i].insert(c);
        }
        hidden_[i].insert(kUnlabelled);
        // Labels beyond the list are hidden as well when a selection is given.
        only_[i] = shown;
      }
    }
    if (options_.mode != "splat" && options_.mode != "points") {
      throw Error("<command line>", "--mode", "splat or points", options_.mode);
    }
    for (const auto& m : models_) {
      if (splat() && !m.frames) {
        throw Error(m.name, "--mode splat", "a model the rasterizer can render", "none given");
      }
    }
    checkColorMode(options_.color);
    window_->SetSize(options_.width, options_.height);
    window_->SetWindowName("sadsplat view");
    const double w = 1.0 / static_cast<double>(models_.size());
    for (std::size_t i = 0; i < models_.size(); ++i) {
      vtkNew<vtkRenderer> r;
      r->SetViewport(i * w, 0.0, (i + 1) * w, 1.0);
      r->SetBackground(options_.background[0] / 255.0, options_.background[1] / 255.0,
                       options_.background[2] / 255.0);
      if (i > 0) r->SetActiveCamera(renderers_[0]->GetActiveCamera());  // linked cameras
      window_->AddRenderer(r);
      renderers_.push_back(r);
    }
    window_->SetAlphaBitPlanes(1);
    window_->SetMultiSamples(0);
    resetCamera();
    rebuild();
    renderFrames(1);
  }

  vtkRenderWindow* window() { return window_; }
  bool splat() const { return options_.mode == "splat"; }

  // Splat mode: each viewport's background is the rasterizer's image for the current camera,
  // at 1/`reduction` of the viewport's resolution.
  void renderFrames(int reduction) {
    if (!splat()) return;
    const int* size = window_->GetSize();
    for (std::size_t i = 0; i < models_.size(); ++i) {
      const int w = std::max(1, size[0] / static_cast<int>(models_.size()) / reduction);
      const int h = std::max(1, size[1] / reduction);
      io::FrameRequest request;
      request.camera = cameraFor(w, h);
      request.content = options_.color == ColorMode::kClass ? io::FrameContent::kClasses
                        : isScalarMode(options_.color)      ? io::FrameContent::kScalar
                                                            : io::FrameContent::kRgb;
      const ColorMode mode = options_.color;
      request.scalar = [mode](const GaussianPoint& p) { return scalarValue(p, mode); };
      const bool all = hidden_[i].empty() && (only_.count(i) == 0 || only_.at(i).empty());
      if (!all) request.visible = [this, i](std::uint32_t label) { return visible(i, label); };
      const io::SplatFrame frame = models_[i].frames(request);
      renderers_[i]->SetBackgroundTexture(texture(i, frame));
      renderers_[i]->TexturedBackgroundOn();
    }
  }

  // The VTK camera as a pinhole camera of w x h pixels (square pixels, centred principal point);
  // the scene camera itself while the view is the one --view named.
  io::PinholeCamera cameraFor(int w, int h) const {
    io::PinholeCamera cam;
    if (exact_) {
      cam = *exact_;
      const double sx = static_cast<double>(w) / cam.width,
                   sy = static_cast<double>(h) / cam.height;
      cam.fx *= sx, cam.cx *= sx, cam.fy *= sy, cam.cy *= sy;
      cam.width = w, cam.height = h;
      return cam;
    }
    vtkCamera* c = renderers_[0]->GetActiveCamera();
    double p[3], f[3], u[3];
    c->GetPosition(p);
    c->GetFocalPoint(f);
    c->GetViewUp(u);
    const Eigen::Vector3d eye(p[0], p[1], p[2]);
    const Eigen::Vector3d forward = (Eigen::Vector3d(f[0], f[1], f[2]) - eye).normalized();
    const Eigen::Vector3d down = -(Eigen::Vector3d(u[0], u[1], u[2]) -
                                   forward.dot(Eigen::Vector3d(u[0], u[1], u[2])) * forward)
                                      .normalized();
    const Eigen::Vector3d right = down.cross(forward);
    Eigen::Matrix3d R;
    R.row(0) = right;
    R.row(1) = down;
    R.row(2) = forward;
    const Eigen::Quaterniond q(R);
    cam.qvec = {q.w(), q.x(), q.y(), q.z()};
    const Eigen::Vector3d t = -R * eye;
    cam.tvec = {t.x(), t.y(), t.z()};
    cam.width = w;
    cam.height = h;
    cam.fy = 0.5 * h / std::tan(0.5 * c->GetViewAngle() * kPi / 180.0);
    cam.fx = cam.fy;
    cam.cx = 0.5 * w;
    cam.cy = 0.5 * h;
    return cam;
  }

  // The frame composited over the background in the current colouring, as a texture.
  vtkSmartPointer<vtkTexture> texture(std::size_t model, const io::SplatFrame& frame) const {
    const ViewModel& m = models_[model];
    vtkNew<vtkImageData> image;
    image->SetDimensions(frame.width, frame.height, 1);
    image->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
    auto* out = static_cast<std::uint8_t*>(image->GetScalarPointer());
    const auto lut = lookupTable();
    const auto& bg = options_.background;
    for (int y = 0; y < frame.height; ++y) {
      for (int x = 0; x < frame.width; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * frame.width + x;
        // VTK's rows run bottom-up.
        std::uint8_t* o =
            out + (static_cast<std::size_t>(frame.height - 1 - y) * frame.width + x) * 3;
        const float a = frame.alpha[i];
        if (!frame.classes.empty()) {
          const std::int16_t c = frame.classes[i];
          const auto rgb = c >= 0    ? classColor(m, static_cast<std::uint32_t>(c))
                           : c == -2 ? classColor(m, kUnlabelled)
                                     : bg;
          std::copy(rgb.begin(), rgb.end(), o);
        } else if (!frame.scalar.empty()) {
          double rgb[3];
          lut->GetColor(frame.scalar[i], rgb);
          for (int k = 0; k < 3; ++k) {
            o[k] = static_cast<std::uint8_t>(std::lround(255.0 * rgb[k] * a + bg[k] * (1.0 - a)));
          }
        } else {
          for (int k = 0; k < 3; ++k) {
            o[k] = static_cast<std::uint8_t>(
                std::min(255.0, std::round(frame.rgb[3 * i + k] + bg[k] * (1.0 - a))));
          }
        }
      }
    }
    vtkNew<vtkTexture> tex;
    tex->SetInputData(image);
    tex->InterpolateOff();
    return tex.GetPointer();
  }

  // Camera moves: a quick frame while the mouse drags, the full one when it stops.
  void cameraMoving() {
    exact_.reset();
    renderFrames(4);
    window_->Render();
  }
  void cameraStopped() {
    renderFrames(1);
    window_->Render();
  }

  void checkColorMode(ColorMode mode) const {
    for (const auto& m : models_) {
      if ((mode == ColorMode::kConfidence || mode == ColorMode::kGate) &&
          (!m.has_semantic || m.semantic_only)) {
        throw Error(m.name, "--color " + colorModeName(mode),
                    "a model with sadsplat's semantic fields (a trained model.ply / model.pcd)",
                    m.semantic_only ? "a plain semantic cloud" : "a file without them");
      }
      if (mode == ColorMode::kClass && !m.has_semantic) {
        throw Error(m.name, "--color class", "a model with class labels (sadsplat's model.ply)",
                    "a file without semantic properties (try --color rgb)");
      }
    }
  }

  void rebuild() {
    for (std::size_t i = 0; i < models_.size(); ++i) {
      renderers_[i]->RemoveAllViewProps();
      if (!splat()) renderers_[i]->AddActor(splatActor(i));
      renderers_[i]->AddActor2D(titleActor(i));
      if (isScalarMode(options_.color)) {
        renderers_[i]->AddActor2D(scalarBar());
      } else if (options_.color == ColorMode::kClass && !models_[i].classes.empty()) {
        renderers_[i]->AddActor2D(legend(i));
      }
    }
  }

  void resetCamera() {
    vtkCamera* camera = renderers_[0]->GetActiveCamera();
    if (!options_.view.empty()) {
      for (const auto& [name, cam] : models_[0].cameras) {
        if (name != options_.view) continue;
        const auto r = cam.rotation();
        const Eigen::Matrix3d R =
            Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(r.data());
        const Eigen::Vector3d t(cam.tvec[0], cam.tvec[1], cam.tvec[2]);
        const Eigen::Vector3d c = -R.transpose() * t;
        const Eigen::Vector3d forward = R.transpose() * Eigen::Vector3d(0, 0, 1);
        const Eigen::Vector3d up = -(R.transpose() * Eigen::Vector3d(0, 1, 0));
        camera->SetPosition(c.x(), c.y(), c.z());
        camera->SetFocalPoint(c.x() + forward.x(), c.y() + forward.y(), c.z() + forward.z());
        camera->SetViewUp(up.x(), up.y(), up.z());
        camera->SetViewAngle(2.0 * std::atan(0.5 * cam.height / cam.fy) * 180.0 / kPi);
        for (auto& ren : renderers_) ren->ResetCameraClippingRange();
        exact_ = cam;
        return;
      }
      std::string known;
      for (std::size_t k = 0; k < models_[0].cameras.size() && k < 4; ++k) {
        known += (k ? ", " : "") + models_[0].cameras[k].first;
      }
      throw Error(models_[0].name, "--view " + options_.view,
                  models_[0].cameras.empty()
                      ? "a run directory whose scene (run.json) is a scene cache"
                      : "a view of the run's scene, e.g. " + known,
                  options_.view);
    }
    exact_.reset();
    const SceneFrame f = sceneFrame(models_[0]);
    // Any horizontal direction: the one of x (or y) orthogonal to up.
    Eigen::Vector3d side = Eigen::Vector3d::UnitY().cross(f.up);
    if (side.norm() < 1e-6) side = Eigen::Vector3d::UnitX().cross(f.up);
    const Eigen::Vector3d back = f.up.cross(side.normalized()).normalized();
    const double elevation = 45.0 * kPi / 180.0;
    const double distance = 0.55 * f.extent / std::tan(15.0 * kPi / 180.0);
    const Eigen::Vector3d eye =
        f.centre + distance * (std::sin(elevation) * f.up + std::cos(elevation) * back);
    camera->SetViewAngle(30.0);
    camera->SetFocalPoint(f.centre.x(), f.centre.y(), f.centre.z());
    camera->SetPosition(eye.x(), eye.y(), eye.z());
    camera->SetViewUp(f.up.x(), f.up.y(), f.up.z());
    camera->OrthogonalizeViewUp();
    for (auto& ren : renderers_) ren->ResetCameraClippingRange();
  }

  // Interactive keys; returns whether the key was one of sadsplat's.
  bool key(char k, std::ostream* log) {
    if (k == 'c') {
      static const ColorMode kOrder[] = {ColorMode::kClass, ColorMode::kRgb, ColorMode::kConfidence,
                                         ColorMode::kGate, ColorMode::kOpacity};
      for (int step = 1; step <= 5; ++step) {
        int at = 0;
        while (kOrder[at] != options_.color) ++at;
        const ColorMode next = kOrder[(at + step) % 5];
        try {
          checkColorMode(next);
        } catch (const Error&) {
          continue;
        }
        options_.color = next;
        break;
      }
      if (log) *log << "colour: " << colorModeName(options_.color) << "\n";
    } else if (k >= '1' && k <= '9') {
      const std::uint32_t c = static_cast<std::uint32_t>(k - '1');
      for (auto& h : hidden_) {
        if (h.count(c)) {
          h.erase(c);
        } else {
          h.insert(c);
        }
      }
      for (auto& o : only_) o.second.clear();
      if (log) *log << "class " << c << (hidden_[0].count(c) ? " hidden" : " shown") << "\n";
    } else if (k == 'a') {
      for (auto& h : hidden_) h.clear();
      only_.clear();
    } else if (k == 'v') {
      options_.view.clear();
      resetCamera();
    } else {
      return false;
    }
    rebuild();
    renderFrames(1);
    window_->Render();
    return true;
  }

  void saveScreenshot(const std::string& path) { saveWindowPng(window_, path); }

 private:
  bool visible(std::size_t model, std::uint32_t label) const {
    const auto it = only_.find(model);
    if (it != only_.end() && !it->second.empty()) return it->second.count(label) > 0;
    return hidden_[model].count(label) == 0;
  }

  vtkSmartPointer<vtkActor> splatActor(std::size_t model) const {
    const ViewModel& m = models_[model];
    vtkNew<vtkPoints> points;
    points->SetDataTypeToFloat();
    vtkNew<vtkFloatArray> radius;
    radius->SetName("radius");
    vtkNew<vtkFloatArray> opacity;
    opacity->SetName("opacity");
    vtkNew<vtkUnsignedCharArray> colors;
    colors->SetName("colors");
    colors->SetNumberOfComponents(3);
    vtkNew<vtkFloatArray> values;
    values->SetName("values");
    for (const GaussianPoint& p : m.gaussians) {
      if (!visible(model, p.label)) continue;
      points->InsertNextPoint(p.x, p.y, p.z);
      // A disc cannot show an ellipsoid's shape: its radius is the geometric mean of the two
      // largest axes (a flat Gaussian seen face-on covers about that area; the largest axis
      // alone made every elongated Gaussian a large disc).
      float s[3] = {p.scale[0], p.scale[1], p.scale[2]};
      std::sort(s, s + 3);
      radius->InsertNextValue(
          static_cast<float>(std::exp(0.5f * (s[1] + s[2])) * options_.splat_scale));
      opacity->InsertNextValue(1.0f / (1.0f + std::exp(-p.opacity)));
      if (isScalarMode(options_.color)) {
        values->InsertNextValue(scalarValue(p, options_.color));
      } else {
        const auto rgb = options_.color == ColorMode::kClass ? classColor(m, p.label) : dcColor(p);
        colors->InsertNextTypedTuple(rgb.data());
      }
    }
    vtkNew<vtkPolyData> poly;
    poly->SetPoints(points);
    poly->GetPointData()->AddArray(radius);
    poly->GetPointData()->AddArray(opacity);
    vtkNew<vtkPointGaussianMapper> mapper;
    mapper->SetInputData(poly);
    mapper->SetScaleArray("radius");
    mapper->SetScaleFactor(1.0);
    mapper->SetOpacityArray("opacity");
    mapper->SetEmissive(0);  // emissive splats add up and wash colours out
    // Each splat is drawn opaque over its footprint: the disc where the Gaussian's own alpha,
    // opacity x exp(-d^2 / 2), is at least 1/4 (radius 1.67 sigma at opacity 1, none below 1/4).
    // Opaque discs need no ordering and keep class colours exact; blending translucent sprites
    // in VTK (depth-tested, in data order) left holes and dimmed whole regions.
    mapper->SetSplatShaderCode(
        "//VTK::Color::Impl\n"
        "float dist2 = dot(offsetVCVSOutput.xy, offsetVCVSOutput.xy);\n"
        "if (opacity < 0.25 || dist2 > 2.0 * log(4.0 * opacity)) { discard; }\n"
        "opacity = 1.0;\n");
    mapper->SetTriangleScale(1.7f);
    if (isScalarMode(options_.color)) {
      poly->GetPointData()->SetScalars(values);
      mapper->SetLookupTable(lookupTable());
      mapper->SetScalarRange(0.0, 1.0);
      mapper->SetColorModeToMapScalars();
    } else {
      poly->GetPointData()->SetScalars(colors);
      mapper->SetColorModeToDirectScalars();
    }
    mapper->ScalarVisibilityOn();
    vtkNew<vtkActor> actor;
    actor->SetMapper(mapper);
    actor->ForceOpaqueOn();
    return actor;
  }

  static vtkSmartPointer<vtkLookupTable> lookupTable() {
    vtkNew<vtkLookupTable> lut;
    lut->SetHueRange(0.667, 0.0);  // blue (0) to red (1)
    lut->SetTableRange(0.0, 1.0);
    lut->Build();
    return lut.GetPointer();
  }

  vtkSmartPointer<vtkScalarBarActor> scalarBar() const {
    vtkNew<vtkScalarBarActor> bar;
    bar->SetLookupTable(lookupTable());
    bar->SetTitle(colorModeName(options_.color).c_str());
    bar->SetNumberOfLabels(5);
    bar->SetMaximumWidthInPixels(80);
    bar->GetPositionCoordinate()->SetValue(0.88, 0.1);
    bar->SetHeight(0.8);
    return bar.GetPointer();
  }

  vtkSmartPointer<vtkLegendBoxActor> legend(std::size_t model) const {
    const ViewModel& m = models_[model];
    vtkNew<vtkLegendBoxActor> box;
    vtkNew<vtkPlaneSource> square;
    square->Update();
    std::vector<std::uint32_t> shown;
    for (std::uint32_t c = 0; c < m.classes.size(); ++c) {
      if (visible(model, c)) shown.push_back(c);
    }
    box->SetNumberOfEntries(static_cast<int>(shown.size()));
    for (std::size_t k = 0; k < shown.size(); ++k) {
      const auto& c = m.classes[shown[k]];
      double rgb[3] = {c.color[0] / 255.0, c.color[1] / 255.0, c.color[2] / 255.0};
      box->SetEntry(static_cast<int>(k), square->GetOutput(),
                    (std::to_string(shown[k] + 1) + " " + c.name).c_str(), rgb);
    }
    box->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    box->GetPositionCoordinate()->SetValue(0.01, 0.01);
    box->GetPosition2Coordinate()->SetCoordinateSystemToNormalizedViewport();
    box->GetPosition2Coordinate()->SetValue(0.22, std::min(0.5, 0.05 * shown.size()));
    box->UseBackgroundOn();
    box->SetBackgroundColor(0.1, 0.1, 0.12);
    box->SetBackgroundOpacity(0.8);
    return box.GetPointer();
  }

  vtkSmartPointer<vtkTextActor> titleActor(std::size_t model) const {
    const ViewModel& m = models_[model];
    std::size_t drawn = 0;
    for (const auto& p : m.gaussians) drawn += visible(model, p.label);
    std::ostringstream text;
    text << m.name << ": " << drawn << " of " << m.gaussians.size() << " Gaussians ("
         << colorModeName(options_.color) << ")";
    vtkNew<vtkTextActor> title;
    title->SetInput(text.str().c_str());
    title->GetTextProperty()->SetFontSize(16);
    title->GetTextProperty()->SetColor(0.9, 0.9, 0.9);
    title->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    title->GetPositionCoordinate()->SetValue(0.01, 0.95);
    return title.GetPointer();
  }

  std::vector<ViewModel> models_;
  SplatViewOptions options_;
  std::vector<std::set<std::uint32_t>> hidden_;
  std::map<std::size_t, std::set<std::uint32_t>> only_;
  vtkNew<vtkRenderWindow> window_;
  std::vector<vtkSmartPointer<vtkRenderer>> renderers_;
  std::optional<io::PinholeCamera> exact_;  // the --view camera until the user moves
};

void onInteraction(vtkObject*, unsigned long event, void* client, void*) {
  auto* scene = static_cast<SplatScene*>(client);
  if (event == vtkCommand::EndInteractionEvent) {
    scene->cameraStopped();
  } else {
    scene->cameraMoving();
  }
}

}  // namespace

std::string keyHelp() {
  return "keys: c next colouring (class, rgb, confidence, gate, opacity) | 1-9 show/hide class "
         "1-9 (legend numbers) | a show all classes | v back to the aerial view | mouse: rotate, "
         "shift+drag pan, wheel zoom | q quit\n";
}

void showModels(const std::vector<ViewModel>& models, const SplatViewOptions& options,
                std::ostream* log) {
  if (models.empty() || models.size() > 2) {
    throw Error("<command line>", "models", "one model, or two with --compare",
                std::to_string(models.size()) + " models");
  }
  if (options.width < 16 || options.height < 16 || options.width > 8192 || options.height > 8192) {
    throw Error("<command line>", "--size", "WIDTHxHEIGHT between 16 and 8192",
                std::to_string(options.width) + "x" + std::to_string(options.height));
  }
  if (!(options.splat_scale > 0)) {
    throw Error("<command line>", "--splat-scale", "a positive factor",
                std::to_string(options.splat_scale));
  }
  SplatScene scene(models, options);  // validates classes, colouring and view first
  requireDisplay(options.screenshot.empty() ? "sadsplat view" : options.screenshot);
  if (!options.screenshot.empty()) {
    scene.window()->SetOffScreenRendering(1);
    scene.saveScreenshot(options.screenshot);
    if (log) *log << "wrote " << options.screenshot << "\n";
    return;
  }
  vtkNew<vtkRenderWindowInteractor> interactor;
  vtkNew<KeyStyle> style;
  style->on_key = [&](char k) { return scene.key(k, log); };
  if (scene.splat()) {
    vtkNew<vtkCallbackCommand> moved;
    moved->SetCallback(onInteraction);
    moved->SetClientData(&scene);
    style->AddObserver(vtkCommand::InteractionEvent, moved);
    style->AddObserver(vtkCommand::EndInteractionEvent, moved);
  }
  interactor->SetInteractorStyle(style);
  interactor->SetRenderWindow(scene.window());
  if (log) *log << keyHelp() << std::flush;
  scene.window()->Render();
  interactor->Start();
}

}  // namespace viz
}  // namespace sadsplat
