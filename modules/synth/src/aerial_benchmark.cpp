#include "sadsplat/synth/aerial_benchmark.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <sstream>
#include <thread>

#include "sadsplat/common/error.h"
#include "sadsplat/geo/annotation_views.h"

namespace sadsplat {
namespace synth {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Vec3 {
  float x, y, z;
};
Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
float dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
Vec3 normalize(Vec3 a) {
  const float n = std::sqrt(dot(a, a));
  return {a.x / n, a.y / n, a.z / n};
}

// A posed camera: world-to-camera rows (right, down, forward) and centre.
struct Pose {
  Vec3 centre;
  Vec3 rows[3];
};

// The rows of a camera looking along `forward` with its image's x axis level (right = forward x
// up, down = forward x right); `forward` must not be vertical.
void lookAlong(const Vec3& forward, Pose* p) {
  const Vec3 right = normalize(cross(forward, {0, 0, 1}));
  p->rows[0] = right;
  p->rows[1] = cross(forward, right);
  p->rows[2] = forward;
}

// View i orbits tile i % tiles^2 (the whole world when tiles = 1) as the j-th of its views.
Pose orbitPose(const World& world, const SynthOptions& o, int i) {
  const std::uint64_t s = o.seed;
  const int tiles = world.tiles(), per_tile_count = tiles * tiles;
  const int tile = i % per_tile_count, j = i / per_tile_count;
  const int orbit_views = (o.views + per_tile_count - 1) / per_tile_count;
  const double tile_extent = world.extent() / tiles;
  const double tile_x = (2 * (tile % tiles) - tiles + 1) * tile_extent;
  const double tile_y = (2 * (tile / tiles) - tiles + 1) * tile_extent;
  const double theta = 2 * kPi * j / orbit_views + 0.03 * (hash01(s, 41, i) - 0.5);
  const double phase = 2 * kPi * hash01(s, 42, tile), phase2 = 2 * kPi * hash01(s, 43, tile);
  const double pitch = (42.0 + 14.0 * std::sin(2 * theta + phase)) * kPi / 180.0;
  const double base = 0.85 * tile_extent / std::tan(o.horizontal_fov_deg * kPi / 360.0);
  const double dist = base * (1.0 + 0.08 * std::sin(3 * theta + phase2));
  const Vec3 target = {static_cast<float>(tile_x + 8 * (hash01(s, 44, i) - 0.5)),
                       static_cast<float>(tile_y + 8 * (hash01(s, 45, i) - 0.5)), 0.f};
  Pose p;
  p.centre = {static_cast<float>(tile_x + dist * std::cos(pitch) * std::cos(theta)),
              static_cast<float>(tile_y + dist * std::cos(pitch) * std::sin(theta)),
              static_cast<float>(dist * std::sin(pitch))};
  lookAlong(normalize(target - p.centre), &p);
  return p;
}

// Photo i of a grid mission (gridLayout): line i / per_line, flown north on even lines and south
// on odd ones; the camera looks straight down with a little gimbal jitter (<= 1 degree).
Pose gridPose(const World& world, const SynthOptions& o, int i) {
  const GridLayout g = gridLayout(o);
  const std::uint64_t s = o.seed;
  const int line = i / g.per_line, k = i % g.per_line;
  const double half = 0.9 * world.extent();
  const double x = -half + line * g.across_spacing + 1.0 * (hash01(s, 61, i) - 0.5);
  const int along = (line % 2 == 0) ? k : g.per_line - 1 - k;
  const double y = -half + along * g.along_spacing + 1.0 * (hash01(s, 62, i) - 0.5);
  const double z = g.altitude + 2.0 * (hash01(s, 63, i) - 0.5);
  const double heading = (line % 2 == 0 ? 0.0 : kPi) + 0.03 * (hash01(s, 64, i) - 0.5);
  const double tilt = 0.017 * hash01(s, 65, i), tilt_dir = 2 * kPi * hash01(s, 66, i);
  Pose p;
  p.centre = {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)};
  const Vec3 forward = normalize({static_cast<float>(std::sin(tilt) * std::cos(tilt_dir)),
                                  static_cast<float>(std::sin(tilt) * std::sin(tilt_dir)),
                                  static_cast<float>(-std::cos(tilt))});
  // Flying north (heading 0) the image's top is north: right = east, down = south.
  const Vec3 right0 = {static_cast<float>(std::cos(heading)), static_cast<float>(std::sin(heading)),
                       0.f};
  const Vec3 down = normalize(cross(forward, right0));
  const Vec3 right = cross(down, forward);
  p.rows[0] = right;
  p.rows[1] = down;
  p.rows[2] = forward;
  return p;
}

// An oblique pass of a grid-oblique capture: photo j of pass `direction` (0 north, 1 east,
// 2 south, 3 west) flies the grid of a quarter of the oblique views at the nadir grid's altitude,
// the camera pitched kObliquePitchDeg from nadir towards `direction`, its footprint centred on
// the grid position.
Pose obliquePose(const World& world, const SynthOptions& o, int i) {
  const int nadir = nadirViews(o), oblique = o.views - nadir;
  const int direction = (i - nadir) % 4, j = (i - nadir) / 4;
  SynthOptions pass = o;
  pass.capture = Capture::kGrid;
  pass.views = std::max(2, (oblique + 3) / 4);
  Pose p = gridPose(world, pass, std::min(j, pass.views - 1));
  p.centre.z =
      static_cast<float>(gridLayout(o).altitude + (p.centre.z - gridLayout(pass).altitude));
  const double pitch = kObliquePitchDeg * kPi / 180.0;
  const double azimuth = kPi / 2 - direction * kPi / 2;  // north = +y, east = +x
  const Vec3 toward = {static_cast<float>(std::cos(azimuth)), static_cast<float>(std::sin(azimuth)),
                       0.f};
  // Flown offset against the look direction, so that each photo's footprint centre lies over
  // its grid position (as oblique mission planners widen the flown area): the passes look at
  // the labelled area, not past its edge.
  const float offset = static_cast<float>(p.centre.z * std::tan(pitch));
  p.centre.x -= toward.x * offset;
  p.centre.y -= toward.y * offset;
  lookAlong(normalize({static_cast<float>(std::sin(pitch) * toward.x),
                       static_cast<float>(std::sin(pitch) * toward.y),
                       static_cast<float>(-std::cos(pitch))}),
            &p);
  return p;
}

Pose viewPose(const World& world, const SynthOptions& o, int i) {
  if (o.capture == Capture::kGridOblique) {
    if (i < nadirViews(o)) {
      SynthOptions nadir = o;
      nadir.capture = Capture::kGrid;
      nadir.views = nadirViews(o);
      return gridPose(world, nadir, i);
    }
    return obliquePose(world, o, i);
  }
  return o.capture == Capture::kGrid ? gridPose(world, o, i) : orbitPose(world, o, i);
}

std::array<double, 4> rotationToQuaternion(const Pose& p) {
  const double R[3][3] = {{p.rows[0].x, p.rows[0].y, p.rows[0].z},
                          {p.rows[1].x, p.rows[1].y, p.rows[1].z},
                          {p.rows[2].x, p.rows[2].y, p.rows[2].z}};
  std::array<double, 4> q{};
  const double tr = R[0][0] + R[1][1] + R[2][2];
  if (tr > 0) {
    const double s = std::sqrt(tr + 1.0) * 2;
    q = {0.25 * s, (R[2][1] - R[1][2]) / s, (R[0][2] - R[2][0]) / s, (R[1][0] - R[0][1]) / s};
  } else {
    int i = 0;
    if (R[1][1] > R[0][0]) i = 1;
    if (R[2][2] > R[i][i]) i = 2;
    const int j = (i + 1) % 3, k = (i + 2) % 3;
    const double s = std::sqrt(1.0 + R[i][i] - R[j][j] - R[k][k]) * 2;
    q[0] = (R[k][j] - R[j][k]) / s;
    q[1 + i] = 0.25 * s;
    q[1 + j] = (R[j][i] + R[i][j]) / s;
    q[1 + k] = (R[k][i] + R[i][k]) / s;
  }
  if (q[0] < 0) {
    for (double& v : q) v = -v;
  }
  return q;
}

float noise(float x, float y, std::uint64_t seed) { return valueNoise(x, y, seed); }

// Texture and light of a surface point seen along `dir` (unit, from the camera).
Vec3 shade(const World& world, const Hit& h, Vec3 dir, Vec3 sun, std::uint64_t seed) {
  const float px = h.p[0], py = h.p[1], pz = h.p[2];
  Vec3 base = {h.color[0], h.color[1], h.color[2]};
  Vec3 n = {h.n[0], h.n[1], h.n[2]};
  float tex = 1.f, spec_strength = 0.f, shininess = 40.f;
  switch (h.material) {
    case Material::kAsphalt:
      tex = 0.88f + 0.2f * noise(px / 1.3f, py / 1.3f, seed + 1) +
            0.06f * noise(px * 3, py * 3, seed + 2);
      break;
    case Material::kMarking:
      break;
    case Material::kPaving: {
      tex = 0.9f + 0.14f * noise(px / 3.f, py / 3.f, seed + 3);
      const float gx = std::fabs(std::remainder(px, 1.5f)),
                  gy = std::fabs(std::remainder(py, 1.5f));
      if (gx < 0.06f || gy < 0.06f) tex *= 0.82f;
      break;
    }
    case Material::kGrass:
      tex = (0.75f + 0.45f * noise(px / 5.f, py / 5.f, seed + 4)) *
            (0.88f + 0.2f * noise(px * 1.5f, py * 1.5f, seed + 5));
      break;
    case Material::kFoliage:
      tex = 0.62f + 0.7f * noise(px / 0.7f + pz * 0.37f, py / 0.7f - pz * 0.29f, seed + 6);
      n = normalize({n.x + 0.5f * (noise(px * 2, pz * 2, seed + 7) - 0.5f),
                     n.y + 0.5f * (noise(py * 2, pz * 2, seed + 8) - 0.5f), n.z});
      break;
    case Material::kRoof:
      tex = (std::fmod(std::fabs(px + 0.3f * py), 0.5f) < 0.25f ? 0.88f : 1.0f) *
            (0.9f + 0.15f * noise(px / 4.f, py / 4.f, seed + 9));
      break;
    case Material::kFlatRoof:
    case Material::kDeck:
      tex = 0.82f + 0.25f * noise(px / 2.f, py / 2.f, seed + 10);
      break;
    case Material::kWall: {
      const float u = std::fabs(n.x) > 0.5f ? py : px;
      const float wu = std::fmod(std::fabs(u), 3.2f), wz = std::fmod(pz, 3.4f);
      if (pz > 1.f && wu > 0.7f && wu < 2.5f && wz > 1.0f && wz < 2.6f) {
        base = {0.13f, 0.16f, 0.21f};  // glass
        spec_strength = 0.5f;
        shininess = 80.f;
      } else {
        tex = 0.95f;
      }
      break;
    }
    case Material::kCarPaint:
      spec_strength = 0.35f;
      break;
    case Material::kField: {
      const float v = -std::sin(0.2f) * px + std::cos(0.2f) * py;
      tex = (0.86f + 0.14f * std::sin(2.f * static_cast<float>(kPi) * v / 0.8f)) *
            (0.85f + 0.25f * noise(px / 8.f, py / 8.f, seed + 11));
      break;
    }
    case Material::kSoil:
      tex = 0.78f + 0.4f * noise(px / 2.5f, py / 2.5f, seed + 12);
      break;
    case Material::kWater:
      n = normalize({0.06f * (noise(px / 1.3f, py / 2.1f, seed + 13) - 0.5f),
                     0.06f * (noise(px / 1.7f, py / 1.1f, seed + 14) - 0.5f), 1.f});
      tex = 0.9f + 0.15f * noise(px / 9.f, py / 9.f, seed + 15);
      spec_strength = 0.9f;
      shininess = 120.f;
      break;
    case Material::kHull:
      tex = 0.9f + 0.1f * noise(px / 3.f, pz / 3.f, seed + 16);
      break;
    case Material::kContainer: {
      const float u = std::fabs(n.x) > 0.5f ? py : px;
      tex = 0.88f + 0.12f * std::sin(2.f * static_cast<float>(kPi) * u / 0.3f);
      break;
    }
    case Material::kSteel:
      spec_strength = 0.15f;
      break;
    case Material::kConcrete: {
      tex = 0.9f + 0.14f * noise(px / 5.f, py / 5.f, seed + 17);
      const float gx = std::fabs(std::remainder(px, 6.f)), gy = std::fabs(std::remainder(py, 6.f));
      if (gx < 0.08f || gy < 0.08f) tex *= 0.85f;
      break;
    }
    case Material::kOutside:
      tex = 0.8f + 0.4f * noise(px / 15.f, py / 15.f, seed + 18);
      break;
  }
  const float o[3] = {px + h.n[0] * 0.03f, py + h.n[1] * 0.03f, pz + h.n[2] * 0.03f};
  const float L[3] = {sun.x, sun.y, sun.z};
  const bool shadow = dot(n, sun) <= 0.f || world.occluded(o, L, 200.f);
  const float diffuse = shadow ? 0.f : std::max(0.f, dot(n, sun));
  const float light = 0.38f + 0.78f * diffuse;
  Vec3 c = {base.x * tex * light, base.y * tex * light, base.z * tex * light};
  if (spec_strength > 0.f && !shadow) {
    const Vec3 half = normalize({sun.x - dir.x, sun.y - dir.y, sun.z - dir.z});
    const float s = spec_strength * std::pow(std::max(0.f, dot(n, half)), shininess);
    c = {c.x + s, c.y + s, c.z + s};
  }
  // Aerial haze with distance.
  const float f = 1.f - std::exp(-h.t / 2200.f);
  const Vec3 haze = {0.72f, 0.77f, 0.83f};
  return {c.x * (1 - f) + haze.x * f, c.y * (1 - f) + haze.y * f, c.z * (1 - f) + haze.z * f};
}

std::uint8_t toByte(float v) {
  return static_cast<std::uint8_t>(std::lround(std::min(1.f, std::max(0.f, v)) * 255.f));
}

void renderView(const World& world, const SynthOptions& o, const Pose& pose, Vec3 sun,
                SynthView* view) {
  const int W = o.width, H = o.height;
  const auto& cam = view->camera;
  view->rgb = {W, H, 3, std::vector<std::uint8_t>(static_cast<std::size_t>(W) * H * 3)};
  view->labels = {W, H, 1, std::vector<std::uint8_t>(static_cast<std::size_t>(W) * H)};
  view->depth.assign(static_cast<std::size_t>(W) * H, 0.f);
  const int threads = o.threads > 0 ? o.threads : std::max(1u, std::thread::hardware_concurrency());
  const int ss = std::max(1, o.samples_per_axis);
  const float origin[3] = {pose.centre.x, pose.centre.y, pose.centre.z};
  // Unit world direction and 1/|camera direction| of the ray through image point (x, y).
  auto ray = [&](double x, double y, float dir[3]) {
    const Vec3 dc = {static_cast<float>((x - cam.cx) / cam.fx),
                     static_cast<float>((y - cam.cy) / cam.fy), 1.f};
    const float inv = 1.f / std::sqrt(dot(dc, dc));
    dir[0] = (pose.rows[0].x * dc.x + pose.rows[1].x * dc.y + pose.rows[2].x) * inv;
    dir[1] = (pose.rows[0].y * dc.x + pose.rows[1].y * dc.y + pose.rows[2].y) * inv;
    dir[2] = (pose.rows[0].z * dc.x + pose.rows[1].z * dc.y + pose.rows[2].z) * inv;
    return inv;
  };
  auto radiance = [&](const float dir[3]) {
    Hit hit;
    if (world.trace(origin, dir, 1e5f, &hit))
      return shade(world, hit, {dir[0], dir[1], dir[2]}, sun, o.seed * 131 + 7);
    const float k = std::min(1.f, std::max(0.f, dir[2] * 4.f));
    return Vec3{0.76f - 0.3f * k, 0.82f - 0.2f * k, 0.9f - 0.05f * k};
  };
  auto rows = [&](int t) {
    for (int v = t; v < H; v += threads) {
      for (int u = 0; u < W; ++u) {
        const std::size_t pix = static_cast<std::size_t>(v) * W + u;
        // Label and depth from the pixel centre; colour averaged over ss x ss sub-pixel rays.
        float dir[3];
        const float inv = ray(u + 0.5, v + 0.5, dir);
        Hit hit;
        if (world.trace(origin, dir, 1e5f, &hit)) {
          view->labels.pixels[pix] = hit.cls;
          view->depth[pix] = hit.t * inv;  // camera z
        } else {
          view->labels.pixels[pix] = io::kIgnoreLabel;
        }
        Vec3 color = {0, 0, 0};
        for (int sy = 0; sy < ss; ++sy) {
          for (int sx = 0; sx < ss; ++sx) {
            ray(u + (sx + 0.5) / ss, v + (sy + 0.5) / ss, dir);
            const Vec3 c = radiance(dir);
            color = {color.x + c.x, color.y + c.y, color.z + c.z};
          }
        }
        const float n = 1.f / (ss * ss);
        view->rgb.pixels[3 * pix] = toByte(color.x * n);
        view->rgb.pixels[3 * pix + 1] = toByte(color.y * n);
        view->rgb.pixels[3 * pix + 2] = toByte(color.z * n);
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(rows, t);
  rows(0);
  for (auto& th : pool) th.join();
}

// Deterministic uniform numbers for point sampling.
class Sequence {
 public:
  explicit Sequence(std::uint64_t seed) : seed_(seed) {}
  float next() { return hash01(seed_, counter_++); }

 private:
  std::uint64_t seed_;
  std::uint64_t counter_ = 0;
};

bool project(const SynthView& v, const float X[3], float* u, float* w, float* z) {
  const auto& c = v.camera;
  double R[9];
  const double qw = c.qvec[0], qx = c.qvec[1], qy = c.qvec[2], qz = c.qvec[3];
  R[0] = 1 - 2 * (qy * qy + qz * qz);
  R[1] = 2 * (qx * qy - qw * qz);
  R[2] = 2 * (qx * qz + qw * qy);
  R[3] = 2 * (qx * qy + qw * qz);
  R[4] = 1 - 2 * (qx * qx + qz * qz);
  R[5] = 2 * (qy * qz - qw * qx);
  R[6] = 2 * (qx * qz - qw * qy);
  R[7] = 2 * (qy * qz + qw * qx);
  R[8] = 1 - 2 * (qx * qx + qy * qy);
  double p[3];
  for (int i = 0; i < 3; ++i)
    p[i] = R[3 * i] * X[0] + R[3 * i + 1] * X[1] + R[3 * i + 2] * X[2] + c.tvec[i];
  if (p[2] <= 1e-3) return false;
  *u = static_cast<float>(c.fx * p[0] / p[2] + c.cx);
  *w = static_cast<float>(c.fy * p[1] / p[2] + c.cy);
  *z = static_cast<float>(p[2]);
  return *u >= 0 && *w >= 0 && *u < c.width && *w < c.height;
}

void samplePoints(const SynthOptions& o, const std::vector<Pose>& poses, SynthScene* scene) {
  Sequence rnd(o.seed * 6700417 + 13);
  const int V = static_cast<int>(scene->views.size());
  const int attempts = o.max_points * 10;
  for (int a = 0; a < attempts && static_cast<int>(scene->points.size()) < o.max_points; ++a) {
    const int i = std::min(V - 1, static_cast<int>(rnd.next() * V));
    const SynthView& v = scene->views[i];
    const int u = std::min(o.width - 1, static_cast<int>(rnd.next() * o.width));
    const int w = std::min(o.height - 1, static_cast<int>(rnd.next() * o.height));
    const std::size_t pix = static_cast<std::size_t>(w) * o.width + u;
    const std::uint8_t cls = v.labels.pixels[pix];
    const float z = v.depth[pix];
    // Any surface, the unlabelled terrain beyond the world included (as structure from motion
    // triangulates whatever the photos show); not the sky (no depth).
    if (z <= 0.f) continue;
    // Back-project the pixel centre; SfM-like noise moves it a little towards the camera, so no
    // point ends up inside a solid.
    const float zn = z * (1.f - 0.0002f * rnd.next());
    const Vec3 dc = {static_cast<float>((u + 0.5 - v.camera.cx) / v.camera.fx),
                     static_cast<float>((w + 0.5 - v.camera.cy) / v.camera.fy), 1.f};
    const Pose& p = poses[i];
    float X[3];
    X[0] = p.centre.x + zn * (p.rows[0].x * dc.x + p.rows[1].x * dc.y + p.rows[2].x);
    X[1] = p.centre.y + zn * (p.rows[0].y * dc.x + p.rows[1].y * dc.y + p.rows[2].y);
    X[2] = p.centre.z + zn * (p.rows[0].z * dc.x + p.rows[1].z * dc.y + p.rows[2].z);
    SynthPoint point;
    std::copy(X, X + 3, point.xyz);
    std::copy(&v.rgb.pixels[3 * pix], &v.rgb.pixels[3 * pix] + 3, point.rgb);
    point.cls = cls;
    for (int j = 0; j < V; ++j) {
      float pu, pv, pz;
      if (!project(scene->views[j], X, &pu, &pv, &pz)) continue;
      const std::size_t q = static_cast<std::size_t>(pv) * o.width + static_cast<int>(pu);
      const float dz = scene->views[j].depth[q];
      if (dz > 0 && std::fabs(dz - pz) < 0.01f * pz) point.track.push_back({j, {pu, pv}});
    }
    if (point.track.size() >= 2) scene->points.push_back(std::move(point));
  }
}

}  // namespace

std::string captureName(Capture capture) {
  return capture == Capture::kGrid          ? "grid"
         : capture == Capture::kGridOblique ? "grid-oblique"
                                            : "orbit";
}

Capture captureFromName(const std::string& name) {
  if (name == "orbit") return Capture::kOrbit;
  if (name == "grid") return Capture::kGrid;
  if (name == "grid-oblique") return Capture::kGridOblique;
  throw Error("<synth>", "--capture", "orbit, grid or grid-oblique", name);
}

int nadirViews(const SynthOptions& o) {
  return o.capture == Capture::kGridOblique ? std::max(2, o.views / 2) : o.views;
}

GridLayout gridLayout(const SynthOptions& options) {
  SynthOptions o = options;
  o.views = nadirViews(options);
  GridLayout g;
  const double tan_h = std::tan(o.horizontal_fov_deg * kPi / 360.0);
  const double tan_v = tan_h * o.height / o.width;
  // Spacing across / along = 2.5 over a square area: lines^2 * 2.5 ~ views.
  g.lines = std::max(1, static_cast<int>(std::lround(std::sqrt(o.views / 2.5))));
  g.per_line = std::max(2, (o.views + g.lines - 1) / g.lines);
  const double span = 1.8 * World::extentOf(o.tiles);
  g.along_spacing = span / (g.per_line - 1);
  g.across_spacing = g.lines > 1 ? span / (g.lines - 1) : 0;
  // 75 % forward overlap: the along-track footprint (the image's short side) is 4 spacings.
  g.altitude = 4 * g.along_spacing / (2 * tan_v);
  g.forward_overlap = 1 - g.along_spacing / (2 * g.altitude * tan_v);
  g.side_overlap = g.lines > 1 ? 1 - g.across_spacing / (2 * g.altitude * tan_h) : 0;
  return g;
}

SynthOptions SynthOptions::demo(SceneKind kind, std::uint64_t seed) {
  SynthOptions o;
  o.kind = kind;
  o.seed = seed;
  o.views = 70;
  o.width = 320;
  o.height = 180;
  o.max_points = 6000;
  return o;
}

SynthOptions SynthOptions::tiledCity(std::uint64_t seed, int tiles) {
  SynthOptions o;
  o.kind = SceneKind::kCity;
  o.seed = seed;
  o.tiles = tiles;
  const int count = tiles * tiles;
  o.views = o.views * count;
  o.max_points = o.max_points * count;
  // The ordinary split on every tile: view i belongs to tile i % count as its (i / count)-th.
  const std::vector<int> labelled = o.labelled, test = o.test;
  o.labelled.clear();
  o.test.clear();
  for (int tile = 0; tile < count; ++tile) {
    for (int j : labelled) o.labelled.push_back(count * j + tile);
    for (int j : test) o.test.push_back(count * j + tile);
  }
  return o;
}

std::string worldId(SceneKind kind, std::uint64_t seed, int tiles) {
  return std::string("synth:") + sceneKindName(kind) + ":" + std::to_string(seed) + ":" +
         std::to_string(tiles);
}

std::optional<World> worldFromId(const std::string& id) {
  std::istringstream in(id);
  std::string prefix, kind, seed, tiles;
  if (!std::getline(in, prefix, ':') || prefix != "synth" || !std::getline(in, kind, ':') ||
      !std::getline(in, seed, ':') || !std::getline(in, tiles)) {
    return std::nullopt;
  }
  try {
    return World(parseSceneKind(kind), std::stoull(seed), std::stoi(tiles));
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

namespace {

// SynthOptions::labelled_auto: the training views a user is advised to annotate.
std::vector<int> chosenLabelledViews(const SynthScene& synth, const SynthOptions& o) {
  io::Scene scene;
  for (std::size_t i = 0; i < synth.views.size(); ++i) {
    io::View view;
    view.name = synth.views[i].name;
    view.camera = synth.views[i].camera;
    view.test = std::find(o.test.begin(), o.test.end(), static_cast<int>(i)) != o.test.end();
    view.train = !view.test;
    scene.views.push_back(std::move(view));
  }
  for (const SynthPoint& p : synth.points) {
    io::ScenePoint sp;
    std::copy(p.xyz, p.xyz + 3, sp.xyz.begin());
    scene.points.push_back(sp);
  }
  geo::AnnotationViewOptions options;
  options.count = std::max<int>(1, static_cast<int>(o.labelled.size()));
  return geo::chooseAnnotationViews(scene, options, "<synth>").picked;
}

}  // namespace

OrthoTruth orthoTruth(const World& world, double gsd) {
  OrthoTruth t;
  t.gsd = gsd;
  const double e = world.extent();
  t.x0 = -e;
  t.y0 = e;
  t.width = t.height = static_cast<int>(std::ceil(2 * e / gsd));
  t.classes.assign(static_cast<std::size_t>(t.width) * t.height, 255);
  t.heights.assign(t.classes.size(), std::numeric_limits<float>::quiet_NaN());
  const float down[3] = {0.f, 0.f, -1.f};
  const float top = world.maxHeight() + 10.f;
  for (int j = 0; j < t.height; ++j) {
    for (int i = 0; i < t.width; ++i) {
      const float origin[3] = {static_cast<float>(t.x0 + (i + 0.5) * gsd),
                               static_cast<float>(t.y0 - (j + 0.5) * gsd), top};
      Hit hit;
      if (world.trace(origin, down, top + 100.f, &hit)) {
        t.classes[static_cast<std::size_t>(j) * t.width + i] = hit.cls;
        t.heights[static_cast<std::size_t>(j) * t.width + i] = hit.p[2];
      }
    }
  }
  return t;
}

SynthScene generate(const SynthOptions& o) {
  if (o.views < 2 || o.width < 16 || o.height < 16) {
    throw Error("<synth>", "views/width/height", "at least 2 views of at least 16x16 pixels",
                std::to_string(o.views) + " views of " + std::to_string(o.width) + "x" +
                    std::to_string(o.height));
  }
  for (int l : o.labelled) {
    if (l < 0 || l >= o.views) {
      throw Error("<synth>", "--labelled", "view indices below " + std::to_string(o.views),
                  std::to_string(l));
    }
  }
  const auto start = std::chrono::steady_clock::now();
  const World world(o.kind, o.seed, o.tiles);
  SynthScene scene;
  scene.classes = world.classes();
  const double sun_azimuth = 2 * kPi * hash01(o.seed, 51),
               sun_elevation = (45 + 15 * hash01(o.seed, 52)) * kPi / 180;
  const Vec3 sun = {static_cast<float>(std::cos(sun_elevation) * std::cos(sun_azimuth)),
                    static_cast<float>(std::cos(sun_elevation) * std::sin(sun_azimuth)),
                    static_cast<float>(std::sin(sun_elevation))};
  const double f = (o.width / 2.0) / std::tan(o.horizontal_fov_deg * kPi / 360.0);
  std::vector<Pose> poses;
  for (int i = 0; i < o.views; ++i) {
    const Pose pose = viewPose(world, o, i);
    poses.push_back(pose);
    SynthView view;
    char name[32];
    std::snprintf(name, sizeof(name), "view_%03d.png", i);
    view.name = name;
    view.camera.width = o.width;
    view.camera.height = o.height;
    view.camera.fx = view.camera.fy = f;
    view.camera.cx = o.width / 2.0;
    view.camera.cy = o.height / 2.0;
    view.camera.qvec = rotationToQuaternion(pose);
    for (int r = 0; r < 3; ++r) view.camera.tvec[r] = -dot(pose.rows[r], pose.centre);
    renderView(world, o, pose, sun, &view);
    scene.views.push_back(std::move(view));
  }
  samplePoints(o, poses, &scene);
  scene.ortho = orthoTruth(world);
  scene.world = worldId(o.kind, o.seed, o.tiles);
  const std::vector<int> labelled = o.labelled_auto ? chosenLabelledViews(scene, o) : o.labelled;
  for (int i = 0; i < o.views; ++i) {
    const bool test = std::find(o.test.begin(), o.test.end(), i) != o.test.end();
    if (test) {
      scene.split.test.push_back(scene.views[i].name);
    } else {
      scene.split.train.push_back(scene.views[i].name);
      if (std::find(labelled.begin(), labelled.end(), i) != labelled.end()) {
        scene.split.labelled.push_back(scene.views[i].name);
      }
    }
  }
  scene.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return scene;
}

io::Scene toScene(const SynthScene& synth) {
  io::Scene scene;
  scene.source = synth.world.empty() ? "synth" : synth.world;
  scene.classes = synth.classes;
  const std::set<std::string> train(synth.split.train.begin(), synth.split.train.end());
  const std::set<std::string> test(synth.split.test.begin(), synth.split.test.end());
  const std::set<std::string> labelled(synth.split.labelled.begin(), synth.split.labelled.end());
  for (const SynthView& v : synth.views) {
    io::View view;
    view.name = v.name;
    view.camera = v.camera;
    view.rgb = v.rgb;
    view.labels = v.labels;
    view.mask = {
        v.rgb.width, v.rgb.height, 1,
        std::vector<std::uint8_t>(static_cast<std::size_t>(v.rgb.width) * v.rgb.height, 255)};
    view.train = train.count(v.name) > 0;
    view.test = test.count(v.name) > 0;
    view.labelled = labelled.count(v.name) > 0;
    scene.views.push_back(std::move(view));
  }
  for (const SynthPoint& p : synth.points) {
    io::ScenePoint sp;
    std::copy(p.xyz, p.xyz + 3, sp.xyz.begin());
    std::copy(p.rgb, p.rgb + 3, sp.rgb.begin());
    scene.points.push_back(sp);
  }
  return scene;
}

SynthStats computeStats(const SynthScene& scene) {
  SynthStats s;
  std::vector<double> counts(scene.classes.size(), 0.0);
  double labelled = 0, total = 0;
  for (const auto& v : scene.views) {
    for (std::uint8_t l : v.labels.pixels) {
      total += 1;
      if (l != io::kIgnoreLabel) {
        counts[l] += 1;
        labelled += 1;
      }
    }
  }
  s.class_share.resize(counts.size());
  for (std::size_t c = 0; c < counts.size(); ++c)
    s.class_share[c] = labelled > 0 ? counts[c] / labelled : 0;
  s.effective_share = total > 0 ? labelled / total : 0;
  return s;
}

}  // namespace synth
}  // namespace sadsplat
