#include "sadsplat/pipeline/ortho_render.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string>
#include <utility>

#include "map_layers.h"
#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/raster_math.h"
#include "sadsplat/gaussians/view_coverage.h"
#include "sadsplat/geo/ground_model.h"
#include "sadsplat/geo/map_objects.h"

namespace sadsplat {
namespace pipeline {
namespace {

using Vec3 = std::array<double, 3>;

double percentile(std::vector<double> v, double p) {
  const std::size_t i = static_cast<std::size_t>(p * (v.size() - 1));
  std::nth_element(v.begin(), v.begin() + i, v.end());
  return v[i];
}

}  // namespace

OrthoGrid footprintGrid(const gaussians::Trainer& trainer, const io::Scene& scene, double gsd,
                        const std::optional<std::array<double, 4>>& bounds) {
  if (!(gsd > 0) || !std::isfinite(gsd)) {
    throw Error("<ortho>", "--gsd", "a ground sample distance > 0 (metres per pixel)",
                std::to_string(gsd));
  }
  const gaussians::GaussianParams g = trainer.parameters();
  const at::Tensor means = g.means.detach().to(at::kCPU, at::kDouble).contiguous();
  const at::Tensor opacity = at::sigmoid(g.opacity_logits.detach().to(at::kCPU, at::kDouble));
  const std::int64_t n = means.size(0);
  const double* m = means.data_ptr<double>();
  const double* o = opacity.data_ptr<double>();

  // The training photos cropped to the middle of their images: a Gaussian one of them shows
  // there is part of what the capture looks at.
  std::vector<gaussians::RasterCamera> middles;
  for (const io::View& v : scene.views) {
    if (!v.train) continue;
    gaussians::RasterCamera c = gaussians::RasterCamera::fromPinhole(v.camera);
    const int w = std::max(1, static_cast<int>(kFootprintImageShare * c.width));
    const int h = std::max(1, static_cast<int>(kFootprintImageShare * c.height));
    c.cx -= 0.5 * (c.width - w), c.cy -= 0.5 * (c.height - h);
    c.width = w, c.height = h;
    middles.push_back(c);
  }
  at::Tensor looked_at = gaussians::viewCounts(means, middles) > 0;
  if (looked_at.sum().item<std::int64_t>() < 2) looked_at = at::ones({n}, at::kBool);
  const bool* in_middle = looked_at.contiguous().data_ptr<bool>();

  const geo::MapFrame local = geo::localMapFrame(geo::sceneUp(scene));
  std::vector<double> e, nn;
  double top = -1e300;
  for (std::int64_t i = 0; i < n; ++i) {
    const Vec3 l = local.toLocal({m[3 * i], m[3 * i + 1], m[3 * i + 2]});
    top = std::max(top, l[2]);
    if (o[i] < 0.1 || !in_middle[i]) continue;
    e.push_back(l[0]);
    nn.push_back(l[1]);
  }
  if (e.size() < 2) {
    throw Error("<ortho>", "model", "Gaussians of opacity >= 0.1 to map", std::to_string(e.size()));
  }
  double e0 = percentile(e, 0.01), e1 = percentile(e, 0.99);
  double n0 = percentile(nn, 0.01), n1 = percentile(nn, 0.99);
  const double margin = 0.02 * std::max(e1 - e0, n1 - n0);
  e0 -= margin, e1 += margin, n0 -= margin, n1 += margin;

  OrthoGrid grid;
  grid.gsd = gsd;
  grid.top = top + 1.0;
  grid.frame = scene.georeference ? geo::utmMapFrame(*scene.georeference, e0, n0, e1, n1) : local;
  // The footprint on the map (the local frame's z is the map's up).
  double fx0 = 1e300, fy0 = 1e300, fx1 = -1e300, fy1 = -1e300;
  for (double a : {e0, e1}) {
    for (double b : {n0, n1}) {
      const auto m = grid.frame.planeToMap(a, b);
      fx0 = std::min(fx0, m[0]), fx1 = std::max(fx1, m[0]);
      fy0 = std::min(fy0, m[1]), fy1 = std::max(fy1, m[1]);
    }
  }
  double x0, y0, x1, y1;
  if (bounds) {
    x0 = (*bounds)[0], y0 = (*bounds)[1], x1 = (*bounds)[2], y1 = (*bounds)[3];
    const auto text = [](double a, double b, double c, double d) {
      std::ostringstream t;
      t << std::fixed << std::setprecision(2) << a << "," << b << "," << c << "," << d;
      return t.str();
    };
    if (!(x1 > x0 && y1 > y0)) {
      throw Error("<ortho>", "--bounds", "xmin,ymin,xmax,ymax with xmax > xmin and ymax > ymin",
                  text(x0, y0, x1, y1));
    }
    if (x1 <= fx0 || x0 >= fx1 || y1 <= fy0 || y0 >= fy1) {
      throw Error("<ortho>", "--bounds",
                  "a rectangle overlapping the model's footprint " + text(fx0, fy0, fx1, fy1) +
                      " (" + grid.frame.crs_name + ")",
                  text(x0, y0, x1, y1));
    }
  } else {
    x0 = std::floor(fx0 / gsd) * gsd, y0 = std::floor(fy0 / gsd) * gsd;
    x1 = std::ceil(fx1 / gsd) * gsd, y1 = std::ceil(fy1 / gsd) * gsd;
  }
  const double w = std::ceil((x1 - x0) / gsd - 1e-9), h = std::ceil((y1 - y0) / gsd - 1e-9);
  if (!(w <= 40000 && h <= 40000)) {
    throw Error("<ortho>", "--gsd",
                "a grid of at most 40000 pixels a side (a larger ground sample distance)",
                std::to_string(static_cast<long long>(w)) + " x " +
                    std::to_string(static_cast<long long>(h)) + " pixels at " +
                    std::to_string(gsd) + " m");
  }
  grid.x0 = x0;
  grid.y0 = y1;
  grid.width = std::max(1, static_cast<int>(w));
  grid.height = std::max(1, static_cast<int>(h));
  return grid;
}

double orthoTop(const gaussians::Trainer& trainer, const geo::MapFrame& frame) {
  const at::Tensor means = trainer.parameters().means.detach().to(at::kCPU, at::kDouble);
  const auto& L = frame.scene_to_local;
  const at::Tensor up = at::tensor({L[6], L[7], L[8]}, means.options());
  return means.numel() ? (means.matmul(up)).max().item<double>() + 1.0 : 1.0;
}

gaussians::RasterCamera orthoCamera(const OrthoGrid& grid, int x_off, int y_off, int w, int h) {
  const geo::MapFrame& f = grid.frame;
  const auto& L = f.scene_to_local;
  // Camera x = map east, y = map south, z = down; pixel = (k / gsd) (x, y) + (cx, cy).
  std::array<double, 9> R{};
  for (int j = 0; j < 3; ++j) {
    R[j] = f.c * L[j] - f.s * L[3 + j];
    R[3 + j] = -f.s * L[j] - f.c * L[3 + j];
    R[6 + j] = -L[6 + j];
  }
  gaussians::RasterCamera cam;
  cam.orthographic = true;
  cam.width = w;
  cam.height = h;
  cam.fx = cam.fy = f.k / grid.gsd;
  cam.cx = (f.bE - grid.x0) / grid.gsd - x_off;
  cam.cy = (grid.y0 - f.bN) / grid.gsd - y_off;
  cam.setRotation(R);
  cam.tvec = {0, 0, grid.top};
  return cam;
}

std::vector<gaussians::RasterCamera> trainingCameras(const io::Scene& scene) {
  std::vector<gaussians::RasterCamera> cameras;
  for (const io::View& v : scene.views) {
    if (v.train) cameras.push_back(gaussians::RasterCamera::fromPinhole(v.camera));
  }
  return cameras;
}

OrthoSurface parseOrthoSurface(const std::string& text, const std::string& field) {
  if (text == "first") return OrthoSurface::kFirst;
  if (text == "blend") return OrthoSurface::kBlend;
  throw Error("<ortho>", field, "first or blend", text);
}

OrthoClassSource parseOrthoClassSource(const std::string& text, const std::string& field) {
  if (text == "views") return OrthoClassSource::kViews;
  if (text == "blend") return OrthoClassSource::kBlend;
  if (text == "first") return OrthoClassSource::kFirst;
  throw Error("<ortho>", field, "first, blend or views", text);
}

namespace {

// World points of the pixels of an orthographic tile at camera depths `depth` ([h, w]): [h w, 3]
// double.
at::Tensor backProject(const gaussians::RasterCamera& cam, const at::Tensor& depth) {
  const int h = cam.height, w = cam.width;
  const auto opts = at::TensorOptions().dtype(at::kDouble);
  const at::Tensor xs = (at::arange(w, opts) + 0.5 - cam.cx) / cam.fx;
  const at::Tensor ys = (at::arange(h, opts) + 0.5 - cam.cy) / cam.fy;
  const at::Tensor pc = at::stack({xs.unsqueeze(0).expand({h, w}), ys.unsqueeze(1).expand({h, w}),
                                   depth.to(at::kDouble)},
                                  2)
                            .reshape({-1, 3});
  // world = R^T p_c + centre (centre = -R^T t)
  const std::array<double, 3> centre = cam.centre();
  const double q[4] = {cam.qvec[0], cam.qvec[1], cam.qvec[2], cam.qvec[3]};
  double R[9];
  gaussians::raster::quatToRotation(q, R);
  // Rows: p_c^T R = (R^T p_c)^T.
  const at::Tensor rotation = at::tensor(std::vector<double>(R, R + 9), opts).view({3, 3});
  return pc.matmul(rotation) + at::tensor(std::vector<double>(centre.begin(), centre.end()), opts);
}

// The grid cut into tiles of at most `tile` pixels a side, row by row.
struct OrthoTile {
  int x_off, y_off, w, h;
  std::size_t cell(int x, int y, const OrthoGrid& grid) const {  // grid index of tile pixel
    return static_cast<std::size_t>(y_off + y) * grid.width + x_off + x;
  }
};
std::vector<OrthoTile> orthoTiles(const OrthoGrid& grid, int tile) {
  std::vector<OrthoTile> tiles;
  for (int y_off = 0; y_off < grid.height; y_off += tile) {
    for (int x_off = 0; x_off < grid.width; x_off += tile) {
      tiles.push_back(
          {x_off, y_off, std::min(tile, grid.width - x_off), std::min(tile, grid.height - y_off)});
    }
  }
  return tiles;
}

// OrthoRenderOptions::gaussian_classes one-hot ([N, classes]) for OrthoClassSource::kViews.
at::Tensor oneHotClasses(const gaussians::Trainer& trainer, const OrthoRenderOptions& options) {
  const int k = trainer.numClasses();
  if (options.gaussian_classes.size() != static_cast<std::size_t>(trainer.numGaussians())) {
    throw Error("<ortho>", "gaussian_classes",
                std::to_string(trainer.numGaussians()) + " classes (one per Gaussian)",
                std::to_string(options.gaussian_classes.size()));
  }
  std::vector<std::int64_t> ids(options.gaussian_classes.begin(), options.gaussian_classes.end());
  const at::Tensor labels = at::tensor(ids, at::kLong).clamp(0, k - 1);
  return at::one_hot(labels, k).to(at::kFloat);
}

// What one tile composites for the class map (OrthoRenderOptions::classes): the trained features
// along the whole ray (kBlend) or in front of the first surface (kFirst), or each class's
// blending weight (kViews: the Gaussians carrying `one_hot`, oneHotClasses made once per map and
// once per relabelling pass).
at::Tensor classFeatures(const gaussians::Trainer& trainer, const gaussians::RasterCamera& camera,
                         const OrthoRenderOptions& options, const at::Tensor& keep,
                         const at::Tensor& one_hot) {
  switch (options.classes) {
    case OrthoClassSource::kFirst:
      return trainer.renderSurface(camera, 0.5, true, keep).features;
    case OrthoClassSource::kViews:
      return trainer.renderCameraWith(camera, one_hot, keep).features;
    case OrthoClassSource::kBlend:
      break;
  }
  return trainer.renderCamera(camera, keep).features;
}

// Per cell and class [h, w, classes], a score whose maximum is the cell's class and its
// confidence, from classFeatures' image (`features`): the cosines of the decoded feature, or with
// OrthoClassSource::kViews each class's share of the blending weight.
at::Tensor classScores(const gaussians::Trainer& trainer, const OrthoRenderOptions& options,
                       const at::Tensor& features) {
  if (options.classes == OrthoClassSource::kViews) {
    return features / features.sum(2, true).clamp_min(1e-12);
  }
  return trainer.classCosines(features);
}

// OrthoRenderOptions::ground_window in cells of the grid (at least one).
int groundWindowCells(const OrthoRenderOptions& options, const OrthoGrid& grid) {
  return std::max(1, static_cast<int>(std::lround(options.ground_window / grid.gsd)));
}

// The ground under the DSM and each class against it (geo::groundHeights, findLowRaisedCells):
// the raised and the ground classes, their heights above the ground, the share of cells near it,
// all what the raised check and the pit fill need. Returns the cells of a raised class lower than
// OrthoRenderOptions::raised_share of its class's height (none with the check off).
std::vector<std::size_t> placeClassesOnGround(const OrthoGrid& grid,
                                              const OrthoRenderOptions& options, int num_classes,
                                              OrthoImages& out) {
  geo::GroundModelOptions ground_options;
  ground_options.window_cells = groundWindowCells(options, grid);
  out.ground =
      geo::groundHeights(out.elevation, out.covered, grid.width, grid.height, ground_options);
  geo::LowRaisedCells low = geo::findLowRaisedCells(
      out.classes, out.elevation, out.ground, num_classes, options.raised_height,
      options.raised_share > 0 ? options.raised_share : 1.0);
  out.class_height_above_ground = low.median_above_ground;
  out.raised_classes = low.raised;
  out.ground_classes = low.ground;
  out.near_ground = low.near_ground;
  if (options.raised_share <= 0) return {};
  return std::move(low.cells);
}

// The `cells` given the most likely class of `allowed` (the tiles that hold one are rendered
// again for their features).
void relabelCells(const gaussians::Trainer& trainer, const OrthoGrid& grid,
                  const OrthoRenderOptions& options, const at::Tensor& keep, int tile,
                  const std::vector<std::size_t>& cells, const std::vector<int>& allowed,
                  OrthoImages& out) {
  const int k = static_cast<int>(trainer.numClasses());
  if (cells.empty()) return;
  const at::Tensor one_hot =
      options.classes == OrthoClassSource::kViews ? oneHotClasses(trainer, options) : at::Tensor();
  std::vector<std::uint8_t> lower(out.classes.size(), 0);
  for (std::size_t c : cells) lower[c] = 1;
  for (const OrthoTile& t : orthoTiles(grid, tile)) {
    bool any = false;
    for (int y = 0; y < t.h && !any; ++y) {
      for (int x = 0; x < t.w && !any; ++x) any = lower[t.cell(x, y, grid)] != 0;
    }
    if (!any) continue;
    const gaussians::RasterCamera camera = orthoCamera(grid, t.x_off, t.y_off, t.w, t.h);
    at::Tensor cosines =
        classScores(trainer, options, classFeatures(trainer, camera, options, keep, one_hot));
    at::Tensor others = at::ones({k}, at::kBool);
    for (int c : allowed) others[c] = false;
    cosines.index_fill_(2, others.nonzero().reshape(-1).to(cosines.device()), -1e30);
    const auto best = cosines.max(2);
    const at::Tensor conf = std::get<0>(best).to(at::kCPU, at::kFloat).contiguous();
    const at::Tensor cls = std::get<1>(best).to(at::kCPU, at::kLong).contiguous();
    for (int y = 0; y < t.h; ++y) {
      for (int x = 0; x < t.w; ++x) {
        const std::size_t d = t.cell(x, y, grid);
        if (!lower[d]) continue;
        const std::size_t s = static_cast<std::size_t>(y) * t.w + x;
        out.classes[d] = static_cast<std::uint8_t>(cls.data_ptr<std::int64_t>()[s]);
        out.confidence[d] = conf.data_ptr<float>()[s];
      }
    }
  }
}

// OrthoRenderOptions::raised_share: the `cells` of a raised class at ground height given the most
// likely ground class (out.ground_classes).
void lowerRaisedCells(const gaussians::Trainer& trainer, const OrthoGrid& grid,
                      const OrthoRenderOptions& options, const at::Tensor& keep, int tile,
                      const std::vector<std::size_t>& cells, OrthoImages& out) {
  out.lowered_cells = static_cast<std::int64_t>(cells.size());
  relabelCells(trainer, grid, options, keep, tile, cells, out.ground_classes, out);
}

// OrthoRenderOptions::trim_classes: the objects' cells outside their Gaussians' hull given the
// class around them (map units: the window's half side).
constexpr double kTrimWindow = 1.0;
void trimObjects(const gaussians::Trainer& trainer, const OrthoGrid& grid,
                 const OrthoRenderOptions& options, const at::Tensor& keep, int tile,
                 OrthoImages& out) {
  const int k = static_cast<int>(trainer.numClasses());
  pcl::PointCloud<GaussianPoint> cloud = trainer.toCloud();
  if (options.gaussian_classes.size() != cloud.size()) {
    throw Error("<ortho>", "gaussian_classes",
                std::to_string(cloud.size()) + " classes (one per Gaussian, for the trim)",
                std::to_string(options.gaussian_classes.size()));
  }
  for (std::size_t g = 0; g < cloud.size(); ++g) cloud[g].label = options.gaussian_classes[g];
  if (keep.defined()) {  // --on-surface: the Gaussians the map is made of
    const at::Tensor kept = keep.to(at::kCPU, at::kBool).contiguous();
    const bool* pk = kept.data_ptr<bool>();
    for (std::size_t g = 0; g < cloud.size(); ++g) {
      if (!pk[g]) cloud[g].label = std::numeric_limits<std::uint32_t>::max();
    }
  }
  const std::vector<std::size_t> cells =
      cellsOutsideObjectHulls(cloud, grid, out, options.trim_classes, options.trim_step,
                              minObjectCells(grid.gsd), options.trim_whole_under);
  // The spill lies over the ground beside the walls: the ground classes where the raised check
  // found them, else every other class.
  std::vector<int> others;
  for (int c = 0; c < k; ++c) {
    const bool trimmed = std::find(options.trim_classes.begin(), options.trim_classes.end(), c) !=
                         options.trim_classes.end();
    const bool ground = out.ground_classes.empty() ||
                        std::find(out.ground_classes.begin(), out.ground_classes.end(), c) !=
                            out.ground_classes.end();
    if (!trimmed && ground) others.push_back(c);
  }
  out.trimmed_cells = static_cast<std::int64_t>(cells.size());
  // Each trimmed cell takes the class most of the allowed cells within kTrimWindow around it
  // have (the surface beside a wall goes on under the spill); one with none around it, the most
  // likely allowed class of its own features.
  std::vector<std::uint8_t> allowed(static_cast<std::size_t>(k), 0);
  for (int c : others) allowed[static_cast<std::size_t>(c)] = 1;
  const int r = std::max(1, static_cast<int>(std::lround(kTrimWindow / grid.gsd)));
  const std::vector<std::size_t> alone =
      geo::takeClassAround(out.classes, out.covered, grid.width, grid.height, cells, allowed, r);
  if (!others.empty()) relabelCells(trainer, grid, options, keep, tile, alone, others, out);
}

// The ground-class cells a check found (geo::findGroundPits / findGroundSpikes) take the level of
// the ground classes around them (an uncovered cell has no class, 255, so its elevation is never
// read). Returns how many.
std::int64_t setToGroundLevel(const geo::GroundOutliers& found, OrthoImages& out) {
  for (std::size_t c : found.cells) out.elevation[c] = found.level[c];
  return static_cast<std::int64_t>(found.cells.size());
}

// OrthoRenderOptions::pit_depth: the ground-class cells in a pit.
void fillGroundPits(const OrthoGrid& grid, const OrthoRenderOptions& options, OrthoImages& out) {
  out.filled_pits = setToGroundLevel(
      geo::findGroundPits(out.classes, out.elevation, out.ground_classes, grid.width, grid.height,
                          groundWindowCells(options, grid), options.pit_depth),
      out);
}

// OrthoRenderOptions::spike_height: the ground-class cells standing above the ground classes
// around them, except those within spike_clearance of a raised class's cell.
void lowerGroundSpikes(const OrthoGrid& grid, const OrthoRenderOptions& options, OrthoImages& out) {
  out.lowered_spikes = setToGroundLevel(
      geo::findGroundSpikes(out.classes, out.elevation, out.ground_classes, grid.width, grid.height,
                            groundWindowCells(options, grid), options.spike_height,
                            out.raised_classes,
                            static_cast<int>(std::lround(options.spike_clearance / grid.gsd))),
      out);
}

}  // namespace

OrthoImages renderOrtho(const gaussians::Trainer& trainer, const OrthoGrid& grid,
                        const OrthoRenderOptions& options, std::ostream* progress, int tile) {
  if ((options.min_views > 0 || options.min_spread_degrees > 0 || options.max_surface_gap > 0) &&
      options.cameras.empty()) {
    throw Error("<ortho>", "cameras",
                "the training cameras (to count the views of each cell, or check the surface)",
                "none");
  }
  // The Gaussians the map is made of (undefined: all).
  at::Tensor keep;
  if (options.max_surface_gap > 0) {
    keep = trainer.renderedDepthResiduals(options.cameras, gaussians::SurfaceDepth::kExpected) <=
           options.max_surface_gap;
    if (progress) {
      *progress << "  on the surface (within " << options.max_surface_gap
                << "): " << keep.sum().item<std::int64_t>() << " of " << keep.numel()
                << " Gaussians\n";
    }
  }
  OrthoImages out;
  out.width = grid.width;
  out.height = grid.height;
  const std::size_t pixels = static_cast<std::size_t>(grid.width) * grid.height;
  out.rgb.assign(3 * pixels, 0);
  out.covered.assign(pixels, 0);
  out.classes.assign(pixels, 255);
  out.elevation.assign(pixels, 0.f);
  out.confidence.assign(pixels, 0.f);
  const bool first_height = options.height == OrthoSurface::kFirst;
  const bool first_class = options.classes == OrthoClassSource::kFirst;
  // kViews: the Gaussians carry their classes one-hot in the tiles' render (its colour, alpha
  // and depth do not depend on the features), so one render gives the map and the class weights.
  const at::Tensor one_hot = options.classes == OrthoClassSource::kViews && trainer.numClasses() > 0
                                 ? oneHotClasses(trainer, options)
                                 : at::Tensor();
  const std::vector<OrthoTile> tiles = orthoTiles(grid, tile);
  int done = 0;
  std::vector<at::Tensor> surface_points, surface_cells;
  for (const OrthoTile& t : tiles) {
    const int x_off = t.x_off, y_off = t.y_off, w = t.w, h = t.h;
    const gaussians::RasterCamera camera = orthoCamera(grid, x_off, y_off, w, h);
    const gaussians::RenderResult r = one_hot.defined()
                                          ? trainer.renderCameraWith(camera, one_hot, keep)
                                          : trainer.renderCamera(camera, keep);
    const at::Tensor rgb = r.rgb.clamp(0, 1).mul(255).round().to(at::kCPU, at::kByte).contiguous();
    at::Tensor covered = r.alpha.to(at::kCPU, at::kFloat) >= 0.5f;
    at::Tensor depth = r.depth.to(at::kCPU, at::kFloat), features = r.features, cls, conf;
    if (first_height || first_class) {
      const gaussians::SurfaceLayer layer = trainer.renderSurface(camera, 0.5, first_class, keep);
      // The same cells: the transmittance falls below 0.5 where the alpha reaches 0.5.
      covered = layer.reached;
      if (first_height) depth = layer.depth;
      if (first_class) features = layer.features;
    }
    if (options.min_views > 0 || options.min_spread_degrees > 0) {
      // The covered cells' surface points, counted against the photos after the last tile.
      const at::Tensor cells = covered.reshape(-1).nonzero().reshape(-1);
      surface_points.push_back(backProject(camera, depth).index_select(0, cells));
      const at::Tensor ys = cells.div(w, "floor") + y_off, xs = cells.remainder(w) + x_off;
      surface_cells.push_back(ys * grid.width + xs);
    }
    covered = covered.to(at::kByte).contiguous();
    depth = depth.contiguous();
    if (trainer.numClasses() > 0) {
      const auto best = classScores(trainer, options, features).max(2);
      conf = std::get<0>(best).to(at::kCPU, at::kFloat).contiguous();
      cls = std::get<1>(best).to(at::kCPU, at::kLong).contiguous();
    }
    const auto* prgb = rgb.data_ptr<std::uint8_t>();
    const auto* pc = covered.data_ptr<std::uint8_t>();
    const float* pd = depth.data_ptr<float>();
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const std::size_t s = static_cast<std::size_t>(y) * w + x;
        const std::size_t d = t.cell(x, y, grid);
        for (int c = 0; c < 3; ++c) out.rgb[3 * d + c] = prgb[3 * s + c];
        if (!pc[s]) continue;
        out.covered[d] = 1;
        out.elevation[d] = static_cast<float>(grid.top - pd[s] + grid.frame.height_offset);
        if (cls.defined()) {
          out.classes[d] = static_cast<std::uint8_t>(cls.data_ptr<std::int64_t>()[s]);
          out.confidence[d] = conf.data_ptr<float>()[s];
        }
      }
    }
    ++done;
    if (progress && tiles.size() > 1) {
      *progress << "\r  ortho tile " << done << "/" << tiles.size() << std::flush;
    }
  }
  if (progress && tiles.size() > 1) *progress << "\n";
  if ((options.min_views > 0 || options.min_spread_degrees > 0) && !surface_points.empty()) {
    const at::Tensor device_probe = trainer.parameters().means;
    const at::Tensor points = at::cat(surface_points).to(device_probe.device());
    const at::Tensor cells = at::cat(surface_cells);
    at::Tensor counts = at::zeros({points.size(0)}, points.options().dtype(at::kInt));
    // The horizontal directions to the photos that see each point, summed as unit vectors: their
    // resultant's length over the count says how one-sided the views are.
    const auto& L = grid.frame.scene_to_local;
    const at::Tensor to_local =
        at::tensor(std::vector<double>(L.begin(), L.end()), points.options()).view({3, 3});
    at::Tensor directions = at::zeros({points.size(0), 2}, points.options());
    int seen_by = 0;
    for (const gaussians::RasterCamera& c : options.cameras) {
      const gaussians::RenderResult r = trainer.renderDepth(c, keep);
      const at::Tensor seen =
          gaussians::seenUnoccluded(points, c, r.depth, r.alpha, options.depth_tolerance);
      counts += seen.to(at::kInt);
      if (options.min_spread_degrees > 0) {
        const std::array<double, 3> centre = c.centre();
        const at::Tensor towards =
            (at::tensor(std::vector<double>(centre.begin(), centre.end()), points.options()) -
             points)
                .matmul(to_local.t())
                .narrow(1, 0, 2);
        directions += towards / towards.norm(2, 1, true).clamp_min(1e-9) *
                      seen.unsqueeze(1).to(points.scalar_type());
      }
      if (progress &&
          (++seen_by % 10 == 0 || seen_by == static_cast<int>(options.cameras.size()))) {
        *progress << "\r  ortho: cells seen from " << seen_by << "/" << options.cameras.size()
                  << " photos" << std::flush;
      }
    }
    if (progress) *progress << "\n";
    at::Tensor unsupported = counts < options.min_views;
    if (options.min_spread_degrees > 0) {
      // Spread = 2 acos(resultant length / count): 2a for photos within +-a of one azimuth.
      const at::Tensor resultant =
          (directions.norm(2, 1) / counts.clamp_min(1).to(points.scalar_type())).clamp(0, 1);
      const at::Tensor spread = at::acos(resultant) * (360.0 / M_PI);
      unsupported = unsupported | (spread < options.min_spread_degrees);
    }
    const at::Tensor few = cells.index_select(0, unsupported.to(at::kCPU).nonzero().reshape(-1));
    const auto* pf = few.data_ptr<std::int64_t>();
    for (std::int64_t i = 0; i < few.numel(); ++i) {
      out.covered[pf[i]] = 0;
      out.classes[pf[i]] = 255;
      out.confidence[pf[i]] = 0.f;
      out.elevation[pf[i]] = 0.f;
    }
    out.few_views = few.numel();
  }
  const bool ground_checks =
      options.raised_share > 0 || options.pit_depth > 0 || options.spike_height > 0;
  if (ground_checks && trainer.numClasses() > 0) {
    const std::vector<std::size_t> low =
        placeClassesOnGround(grid, options, static_cast<int>(trainer.numClasses()), out);
    lowerRaisedCells(trainer, grid, options, keep, tile, low, out);
    std::string checks;
    for (const auto& [on, flag] : {std::pair{options.raised_share > 0, "--raised-check"},
                                   std::pair{options.pit_depth > 0, "--pit-depth"},
                                   std::pair{options.spike_height > 0, "--spike-height"}}) {
      if (on) checks += (checks.empty() ? "" : ", ") + std::string(flag);
    }
    if (out.near_ground < geo::kMinNearGround) {
      if (progress) {
        *progress << "  ortho: warning: " << checks << " skipped: only "
                  << std::lround(100 * out.near_ground)
                  << " % of the classified cells lie near the ground the DSM suggests (pits or "
                     "no visible ground; try --min-views 2)\n";
      }
    } else {
      if (options.pit_depth > 0) fillGroundPits(grid, options, out);
      if (progress && options.raised_share > 0) {
        *progress << "  ortho: " << out.lowered_cells << " cells of a raised class at ground height"
                  << " given the most likely ground class\n";
      }
      if (progress && options.pit_depth > 0) {
        *progress << "  ortho: " << out.filled_pits << " cells of a ground class more than "
                  << options.pit_depth << " below the ground classes around them raised to them\n";
      }
    }
  }
  if (!options.trim_classes.empty() && trainer.numClasses() > 0) {
    trimObjects(trainer, grid, options, keep, tile, out);
    if (progress) {
      *progress << "  ortho: " << out.trimmed_cells
                << " cells of objects outside their Gaussians' hull given another class\n";
    }
  }
  // After the trim: the cells it gave a ground class keep the roof's height until here.
  if (options.spike_height > 0 && trainer.numClasses() > 0 &&
      out.near_ground >= geo::kMinNearGround) {
    lowerGroundSpikes(grid, options, out);
    if (progress) {
      *progress << "  ortho: " << out.lowered_spikes << " cells of a ground class more than "
                << options.spike_height
                << " above the ground classes around them lowered to them\n";
    }
  }
  return out;
}

}  // namespace pipeline
}  // namespace sadsplat
