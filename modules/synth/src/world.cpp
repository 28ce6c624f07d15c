#include "sadsplat/synth/world.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace synth {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

std::uint64_t mix64(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// Deterministic generator (the standard distributions differ between libraries).
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(mix64(seed)) {}
  float uniform() { return static_cast<float>((next() >> 40) * (1.0 / 16777216.0)); }
  float uniform(float lo, float hi) { return lo + (hi - lo) * uniform(); }
  int integer(int lo, int hi) {
    return lo + static_cast<int>(uniform() * (hi - lo + 1) * 0.99999f);
  }
  bool chance(float p) { return uniform() < p; }

 private:
  std::uint64_t next() { return state_ = mix64(state_); }
  std::uint64_t state_;
};

float distanceToGrid(float v, float period) {
  const float m = v - period * std::round(v / period);
  return std::fabs(m);
}

void setColor(float out[3], float r, float g, float b) {
  out[0] = r;
  out[1] = g;
  out[2] = b;
}

}  // namespace

float hash01(std::uint64_t a, std::uint64_t b, std::uint64_t c, std::uint64_t d) {
  const std::uint64_t h = mix64(a ^ mix64(b ^ mix64(c ^ mix64(d))));
  return static_cast<float>((h >> 40) * (1.0 / 16777216.0));
}

float valueNoise(float x, float y, std::uint64_t seed) {
  const float fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<std::int64_t>(fx), iy = static_cast<std::int64_t>(fy);
  float tx = x - fx, ty = y - fy;
  tx = tx * tx * (3 - 2 * tx);
  ty = ty * ty * (3 - 2 * ty);
  auto h = [&](std::int64_t i, std::int64_t j) {
    return hash01(seed, static_cast<std::uint64_t>(i), static_cast<std::uint64_t>(j));
  };
  const float a = h(ix, iy), b = h(ix + 1, iy), c = h(ix, iy + 1), d = h(ix + 1, iy + 1);
  return (a * (1 - tx) + b * tx) * (1 - ty) + (c * (1 - tx) + d * tx) * ty;
}

const char* sceneKindName(SceneKind kind) {
  switch (kind) {
    case SceneKind::kCity:
      return "city";
    case SceneKind::kCountry:
      return "country";
    case SceneKind::kPort:
      return "port";
  }
  return "?";
}

SceneKind parseSceneKind(const std::string& name) {
  if (name == "city") return SceneKind::kCity;
  if (name == "country") return SceneKind::kCountry;
  if (name == "port") return SceneKind::kPort;
  throw Error("<synth>", "--kind", "city, country or port", name);
}

World::World(SceneKind kind, std::uint64_t seed, int tiles)
    : kind_(kind), seed_(seed), tiles_(tiles) {
  if (tiles < 1 || tiles > 8 || (tiles > 1 && kind != SceneKind::kCity)) {
    throw Error("<synth>", "tiles", "1 (any kind) or 2..8 (city)", std::to_string(tiles));
  }
  switch (kind) {
    case SceneKind::kCity:
      buildCity();
      break;
    case SceneKind::kCountry:
      buildCountry();
      break;
    case SceneKind::kPort:
      buildPort();
      break;
  }
  max_height_ = 1.f;
  for (const Object& o : objects_) max_height_ = std::max(max_height_, o.hi[2]);
  buildGrid();
}

void World::addBox(float x0, float y0, float z0, float x1, float y1, float z1, std::uint8_t cls,
                   Material top, Material side, const float color[3]) {
  Object o;
  o.shape = Object::kBox;
  o.lo[0] = std::min(x0, x1);
  o.lo[1] = std::min(y0, y1);
  o.lo[2] = z0;
  o.hi[0] = std::max(x0, x1);
  o.hi[1] = std::max(y0, y1);
  o.hi[2] = z1;
  o.cls = cls;
  o.top = top;
  o.side = side;
  std::copy(color, color + 3, o.color);
  // Keep objects inside the labelled area.
  if (o.lo[0] < -extent_ || o.lo[1] < -extent_ || o.hi[0] > extent_ || o.hi[1] > extent_) return;
  objects_.push_back(o);
}

void World::addTree(float x, float y, float radius, float height, std::uint8_t cls, float shade) {
  if (std::fabs(x) + radius > extent_ || std::fabs(y) + radius > extent_) return;
  Object o;
  o.shape = Object::kEllipsoid;
  const float rz = radius * 0.8f;
  o.lo[0] = x - radius;
  o.lo[1] = y - radius;
  o.lo[2] = height - rz;
  o.hi[0] = x + radius;
  o.hi[1] = y + radius;
  o.hi[2] = height + rz;
  o.cls = cls;
  o.top = o.side = Material::kFoliage;
  setColor(o.color, 0.16f * shade, 0.36f * shade, 0.13f * shade);
  objects_.push_back(o);
}

// ---- city: building, road, tree, grass, car, paved ----------------------------------------------

void World::buildCity() {
  classes_ = {{"building", {220, 20, 60}, "a building"},
              {"road", {128, 64, 128}, "an asphalt road"},
              {"tree", {34, 139, 34}, "a tree"},
              {"grass", {152, 251, 152}, "grass or a lawn"},
              {"car", {0, 0, 142}, "a car"},
              {"paved", {190, 153, 153}, "paved ground, a sidewalk or a plaza"}};
  extent_ = extentOf(tiles_);
  block_ = 40.f;
  road_half_ = 4.f;
  Rng rng(seed_ * 7919 + 1);
  const float inner = block_ / 2 - road_half_ - 3.f;  // half-size of a block's lot area
  // Blocks that do not fit the area draw nothing from rng: tiles = 1 is the scene of old.
  const int blocks = static_cast<int>(std::ceil(extent_ / block_));
  for (int bx = -blocks; bx < blocks; ++bx) {
    for (int by = -blocks; by < blocks; ++by) {
      const float cx = (bx + 0.5f) * block_, cy = (by + 0.5f) * block_;
      if (std::fabs(cx) + block_ / 2 > extent_ + 1 || std::fabs(cy) + block_ / 2 > extent_ + 1)
        continue;
      const float type = hash01(seed_, 11, bx + 100, by + 100);
      if (type < 0.62f) {  // buildings
        const int nx = rng.integer(1, 3), ny = rng.integer(1, 2);
        const float lot_w = 2 * inner / nx, lot_h = 2 * inner / ny;
        const float base_height = rng.uniform(8.f, 30.f);
        for (int i = 0; i < nx; ++i) {
          for (int j = 0; j < ny; ++j) {
            const float x0 = cx - inner + i * lot_w, y0 = cy - inner + j * lot_h;
            const float inset = rng.uniform(0.5f, 2.5f);
            const float h = std::max(5.f, base_height * rng.uniform(0.4f, 1.6f));
            float color[3];
            const float tone = rng.uniform(0.45f, 0.85f);
            setColor(color, tone * rng.uniform(0.85f, 1.1f), tone * rng.uniform(0.8f, 1.0f),
                     tone * rng.uniform(0.75f, 0.95f));
            const Material roof = rng.chance(0.45f) ? Material::kRoof : Material::kFlatRoof;
            addBox(x0 + inset, y0 + inset, 0.f, x0 + lot_w - inset, y0 + lot_h - inset, h, 0, roof,
                   Material::kWall, color);
            if (rng.chance(0.35f)) {  // a smaller upper storey or rooftop structure
              const float sx = (lot_w - 2 * inset) * rng.uniform(0.2f, 0.5f);
              const float sy = (lot_h - 2 * inset) * rng.uniform(0.2f, 0.5f);
              const float ox = x0 + inset + rng.uniform(0.5f, lot_w - 2 * inset - sx - 0.5f);
              const float oy = y0 + inset + rng.uniform(0.5f, lot_h - 2 * inset - sy - 0.5f);
              addBox(ox, oy, h, ox + sx, oy + sy, h + rng.uniform(2.f, 8.f), 0, Material::kFlatRoof,
                     Material::kWall, color);
            }
          }
        }
      } else if (type < 0.85f) {  // park: grass with trees
        const int trees = rng.integer(6, 16);
        for (int t = 0; t < trees; ++t) {
          addTree(cx + rng.uniform(-inner, inner), cy + rng.uniform(-inner, inner),
                  rng.uniform(2.f, 4.f), rng.uniform(4.f, 8.f), 2, rng.uniform(0.8f, 1.2f));
        }
      } else {  // plaza / parking: paved with rows of cars
        for (int row = 0; row < 3; ++row) {
          const float y = cy - inner + 4 + row * (2 * inner - 8) / 2;
          for (float x = cx - inner + 2; x < cx + inner - 3; x += 2.6f) {
            if (!rng.chance(0.7f)) continue;
            float color[3];
            setColor(color, rng.uniform(0.1f, 0.9f), rng.uniform(0.1f, 0.9f),
                     rng.uniform(0.1f, 0.9f));
            addBox(x, y - 2.2f, 0.f, x + 1.8f, y + 2.2f, 1.5f, 4, Material::kCarPaint,
                   Material::kCarPaint, color);
          }
        }
      }
    }
  }
  // Street trees on the sidewalks (their crowns overhang the roads) and cars on the roads.
  const int lines = static_cast<int>(std::floor(extent_ / block_));
  for (int k = -lines; k <= lines; ++k) {
    const float line = k * block_;
    for (float s = -extent_ + 3; s < extent_ - 3; s += rng.uniform(7.f, 12.f)) {
      if (distanceToGrid(s, block_) < road_half_ + 4) continue;
      for (float side : {-1.f, 1.f}) {
        if (!rng.chance(0.55f)) continue;
        const float off = line + side * (road_half_ + 1.8f);
        const float r = rng.uniform(2.2f, 3.4f), h = rng.uniform(5.f, 7.5f);
        if (hash01(seed_, 3, k + 10, static_cast<std::uint64_t>(s + 1000)) < 0.5f) {
          addTree(off, s, r, h, 2, rng.uniform(0.85f, 1.15f));
        } else {
          addTree(s, off, r, h, 2, rng.uniform(0.85f, 1.15f));
        }
      }
    }
    for (float s = -extent_ + 2; s < extent_ - 6; s += rng.uniform(6.f, 18.f)) {
      if (distanceToGrid(s, block_) < road_half_ + 1) continue;  // keep junctions clear
      float color[3];
      setColor(color, rng.uniform(0.05f, 0.95f), rng.uniform(0.05f, 0.9f),
               rng.uniform(0.05f, 0.9f));
      const float lane = line + (rng.chance(0.5f) ? -2.f : 2.f);
      if (rng.chance(0.5f)) {
        addBox(s, lane - 0.9f, 0.f, s + 4.5f, lane + 0.9f, 1.5f, 4, Material::kCarPaint,
               Material::kCarPaint, color);
      } else {
        addBox(lane - 0.9f, s, 0.f, lane + 0.9f, s + 4.5f, 1.5f, 4, Material::kCarPaint,
               Material::kCarPaint, color);
      }
    }
  }
}

// ---- country: field, building, road, tree, grass, bare soil, water -----------------------------

void World::buildCountry() {
  classes_ = {{"field", {255, 200, 80}, "a crop field"},
              {"building", {220, 20, 60}, "a farm building"},
              {"road", {128, 64, 128}, "a country road"},
              {"tree", {34, 139, 34}, "a tree"},
              {"grass", {152, 251, 152}, "a meadow"},
              {"bare soil", {150, 100, 60}, "bare soil"},
              {"water", {0, 120, 255}, "water, a river or a pond"}};
  extent_ = 110.f;
  Rng rng(seed_ * 104729 + 2);
  river_x_ = rng.uniform(-60.f, -30.f);
  auto road_y = [&](float x) { return 12.f * std::sin(x / 30.f + seed_) + 15.f; };
  auto river_x = [&](float y) { return river_x_ + 10.f * std::sin(y / 22.f + 2.f * seed_); };
  // Farmsteads away from the road and the river.
  const int farms = rng.integer(2, 4);
  for (int f = 0, attempts = 0; f < farms && attempts < 200; ++attempts) {
    float fx = rng.uniform(-extent_ + 25, extent_ - 25),
          fy = rng.uniform(-extent_ + 25, extent_ - 25);
    if (std::fabs(fy - road_y(fx)) < 18 || std::fabs(fx - river_x(fy)) < 22) continue;
    ++f;
    const int n = rng.integer(1, 4);
    for (int b = 0; b < n; ++b) {
      const float w = rng.uniform(8.f, 22.f), d = rng.uniform(7.f, 14.f);
      const float x0 = fx + rng.uniform(-14.f, 6.f), y0 = fy + rng.uniform(-14.f, 6.f);
      float color[3];
      const float tone = rng.uniform(0.5f, 0.8f);
      setColor(color, tone, tone * 0.8f, tone * 0.7f);
      addBox(x0, y0, 0.f, x0 + w, y0 + d, rng.uniform(4.f, 9.f), 1, Material::kRoof,
             Material::kWall, color);
    }
    for (int t = 0; t < 5; ++t) {
      addTree(fx + rng.uniform(-22.f, 22.f), fy + rng.uniform(-22.f, 22.f), rng.uniform(2.5f, 4.5f),
              rng.uniform(5.f, 9.f), 3, rng.uniform(0.8f, 1.2f));
    }
  }
  // Tree lines along some field boundaries and groves.
  for (int line = -3; line <= 3; ++line) {
    if (!rng.chance(0.5f)) continue;
    const float y = line * 35.f + 17.5f;
    for (float x = -extent_ + 3; x < extent_ - 3; x += rng.uniform(4.f, 7.f)) {
      if (std::fabs(y - road_y(x)) < 6 || std::fabs(x - river_x(y)) < 10) continue;
      addTree(x, y, rng.uniform(2.f, 3.5f), rng.uniform(5.f, 8.f), 3, rng.uniform(0.8f, 1.2f));
    }
  }
  const int groves = rng.integer(2, 4);
  for (int g = 0; g < groves; ++g) {
    const float gx = rng.uniform(-extent_ + 15, extent_ - 15),
                gy = rng.uniform(-extent_ + 15, extent_ - 15);
    for (int t = 0; t < 25; ++t) {
      const float x = gx + rng.uniform(-15.f, 15.f), y = gy + rng.uniform(-15.f, 15.f);
      if (std::fabs(y - road_y(x)) < 6 || std::fabs(x - river_x(y)) < 10) continue;
      addTree(x, y, rng.uniform(2.5f, 4.5f), rng.uniform(6.f, 11.f), 3, rng.uniform(0.75f, 1.1f));
    }
  }
}

// ---- port: water, ship, container, crane, warehouse, road, ground, tree ------------------------

void World::buildPort() {
  classes_ = {{"water", {0, 120, 255}, "harbour water"},
              {"ship", {255, 0, 0}, "a ship"},
              {"container", {255, 140, 0}, "shipping containers"},
              {"crane", {255, 255, 0}, "a harbour crane"},
              {"warehouse", {220, 20, 60}, "a warehouse"},
              {"road", {128, 64, 128}, "a road"},
              {"ground", {190, 153, 153}, "concrete quay ground"},
              {"tree", {34, 139, 34}, "a tree"}};
  extent_ = 110.f;
  Rng rng(seed_ * 1299709 + 3);
  quay_y_ = rng.uniform(-35.f, -20.f);
  const float container_colors[6][3] = {{0.7f, 0.15f, 0.1f},   {0.1f, 0.3f, 0.6f},
                                        {0.15f, 0.5f, 0.25f},  {0.8f, 0.55f, 0.1f},
                                        {0.55f, 0.55f, 0.55f}, {0.85f, 0.85f, 0.8f}};
  auto container = [&](float x, float y, float z, bool along_x, std::uint8_t cls) {
    const float* c = container_colors[rng.integer(0, 5)];
    float color[3] = {c[0] * rng.uniform(0.85f, 1.1f), c[1] * rng.uniform(0.85f, 1.1f),
                      c[2] * rng.uniform(0.85f, 1.1f)};
    if (along_x) {
      addBox(x, y, z, x + 12.f, y + 2.4f, z + 2.6f, cls, Material::kContainer, Material::kContainer,
             color);
    } else {
      addBox(x, y, z, x + 2.4f, y + 12.f, z + 2.6f, cls, Material::kContainer, Material::kContainer,
             color);
    }
  };
  // Ships along the quay.
  for (float x = -extent_ + 5; x < extent_ - 40;) {
    const float length = rng.uniform(45.f, 95.f), beam = rng.uniform(12.f, 20.f);
    if (x + length > extent_ - 2) break;
    const float y1 = quay_y_ - rng.uniform(2.f, 5.f), y0 = y1 - beam;
    if (y0 < -extent_ + 2) break;
    float hull[3] = {rng.uniform(0.2f, 0.6f), rng.uniform(0.1f, 0.25f), rng.uniform(0.1f, 0.3f)};
    const float deck = rng.uniform(5.f, 8.f);
    addBox(x, y0, 0.f, x + length, y1, deck, 1, Material::kDeck, Material::kHull, hull);
    float white[3] = {0.9f, 0.9f, 0.88f};
    addBox(x + length - 14, y0 + 2, deck, x + length - 4, y1 - 2, deck + rng.uniform(8.f, 14.f), 1,
           Material::kFlatRoof, Material::kWall, white);
    if (rng.chance(0.7f)) {  // deck cargo: containers (labelled as containers)
      for (float cx = x + 4; cx + 12 < x + length - 16; cx += 12.4f) {
        for (float cy = y0 + 1.5f; cy + 2.4f < y1 - 1.5f; cy += 2.5f) {
          const int stack = rng.integer(1, 3);
          for (int s = 0; s < stack; ++s) container(cx, cy, deck + 2.6f * s, true, 2);
        }
      }
    }
    x += length + rng.uniform(8.f, 25.f);
  }
  // Cranes on the quay: two legs and a boom reaching over the water.
  for (float x = -extent_ + 15; x < extent_ - 15; x += rng.uniform(28.f, 45.f)) {
    float color[3] = {0.85f, rng.uniform(0.25f, 0.7f), 0.1f};
    const float y = quay_y_ + 4;
    const float h = rng.uniform(26.f, 36.f);
    addBox(x, y, 0.f, x + 1.2f, y + 1.2f, h, 3, Material::kSteel, Material::kSteel, color);
    addBox(x, y + 12, 0.f, x + 1.2f, y + 13.2f, h, 3, Material::kSteel, Material::kSteel, color);
    addBox(x - 0.4f, quay_y_ - 30.f, h, x + 1.6f, y + 20.f, h + 2.f, 3, Material::kSteel,
           Material::kSteel, color);
    addBox(x - 2.f, y + 2.f, h - 4.f, x + 3.2f, y + 6.f, h, 3, Material::kSteel, Material::kSteel,
           color);
  }
  // Land: a quay road, a cross road grid, container yards, warehouses and a few trees.
  road_half_ = 4.f;
  block_ = 55.f;
  for (float bx = -extent_; bx < extent_; bx += block_) {
    for (float by = quay_y_ + 24.f; by < extent_; by += block_) {
      const float x0 = bx + 6, y0 = by + 6, x1 = std::min(bx + block_ - 6, extent_ - 2),
                  y1 = std::min(by + block_ - 6, extent_ - 2);
      if (x1 - x0 < 14 || y1 - y0 < 14) continue;
      const float type = hash01(seed_, 21, static_cast<std::uint64_t>(bx + 500),
                                static_cast<std::uint64_t>(by + 500));
      if (type < 0.5f) {  // container yard
        for (float y = y0; y + 2.4f < y1; y += 3.2f) {
          for (float x = x0; x + 12 < x1; x += 13.f) {
            if (!rng.chance(0.8f)) continue;
            const int stack = rng.integer(1, 4);
            for (int s = 0; s < stack; ++s) container(x, y, 2.6f * s, true, 2);
          }
        }
      } else if (type < 0.85f) {  // warehouse
        float color[3];
        const float tone = rng.uniform(0.55f, 0.85f);
        setColor(color, tone, tone * rng.uniform(0.9f, 1.0f), tone * rng.uniform(0.85f, 1.0f));
        addBox(x0 + 2, y0 + 2, 0.f, x1 - 2, y1 - 2, rng.uniform(9.f, 15.f), 4, Material::kRoof,
               Material::kWall, color);
      } else {
        for (int t = 0; t < 8; ++t) {
          addTree(rng.uniform(x0, x1), rng.uniform(y0, y1), rng.uniform(2.f, 3.5f),
                  rng.uniform(4.f, 7.f), 7, rng.uniform(0.85f, 1.15f));
        }
      }
    }
  }
}

void World::buildGrid() {
  cells_per_side_ = static_cast<int>(std::ceil(2 * extent_ / cell_));
  const int total = cells_per_side_ * cells_per_side_;
  std::vector<std::vector<int>> lists(total);
  for (int i = 0; i < static_cast<int>(objects_.size()); ++i) {
    const Object& o = objects_[i];
    const int x0 = std::max(0, static_cast<int>((o.lo[0] + extent_) / cell_));
    const int y0 = std::max(0, static_cast<int>((o.lo[1] + extent_) / cell_));
    const int x1 = std::min(cells_per_side_ - 1, static_cast<int>((o.hi[0] + extent_) / cell_));
    const int y1 = std::min(cells_per_side_ - 1, static_cast<int>((o.hi[1] + extent_) / cell_));
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) lists[y * cells_per_side_ + x].push_back(i);
    }
  }
  cell_start_.assign(total + 1, 0);
  for (int c = 0; c < total; ++c)
    cell_start_[c + 1] = cell_start_[c] + static_cast<int>(lists[c].size());
  cell_items_.clear();
  cell_items_.reserve(cell_start_[total]);
  for (const auto& l : lists) cell_items_.insert(cell_items_.end(), l.begin(), l.end());
}

bool World::intersectObject(int index, const float o[3], const float d[3], float tmin, float tmax,
                            Hit* hit) const {
  const Object& ob = objects_[index];
  if (ob.shape == Object::kBox) {
    float t0 = tmin, t1 = tmax;
    int axis = -1;
    float sign = 0;
    for (int a = 0; a < 3; ++a) {
      if (std::fabs(d[a]) < 1e-12f) {
        if (o[a] < ob.lo[a] || o[a] > ob.hi[a]) return false;
        continue;
      }
      float ta = (ob.lo[a] - o[a]) / d[a], tb = (ob.hi[a] - o[a]) / d[a];
      float s = -1;
      if (ta > tb) {
        std::swap(ta, tb);
        s = 1;
      }
      if (ta > t0) {
        t0 = ta;
        axis = a;
        sign = s;
      }
      t1 = std::min(t1, tb);
      if (t0 > t1) return false;
    }
    if (axis < 0) return false;  // the ray starts inside: not a surface hit
    hit->t = t0;
    hit->n[0] = hit->n[1] = hit->n[2] = 0;
    hit->n[axis] = sign;
  } else {
    float c[3], r[3], oc[3], dc[3];
    for (int a = 0; a < 3; ++a) {
      c[a] = 0.5f * (ob.lo[a] + ob.hi[a]);
      r[a] = 0.5f * (ob.hi[a] - ob.lo[a]);
      oc[a] = (o[a] - c[a]) / r[a];
      dc[a] = d[a] / r[a];
    }
    const float A = dc[0] * dc[0] + dc[1] * dc[1] + dc[2] * dc[2];
    const float B = 2 * (oc[0] * dc[0] + oc[1] * dc[1] + oc[2] * dc[2]);
    const float C = oc[0] * oc[0] + oc[1] * oc[1] + oc[2] * oc[2] - 1;
    const float disc = B * B - 4 * A * C;
    if (disc < 0) return false;
    const float t = (-B - std::sqrt(disc)) / (2 * A);
    if (t <= tmin || t > tmax) return false;
    hit->t = t;
    float len = 0;
    for (int a = 0; a < 3; ++a) {
      hit->n[a] = (oc[a] + t * dc[a]) / r[a];
      len += hit->n[a] * hit->n[a];
    }
    len = std::sqrt(len);
    for (int a = 0; a < 3; ++a) hit->n[a] /= len;
  }
  for (int a = 0; a < 3; ++a) hit->p[a] = o[a] + hit->t * d[a];
  hit->object = index;
  hit->cls = ob.cls;
  hit->material = hit->n[2] > 0.7f ? ob.top : ob.side;
  std::copy(ob.color, ob.color + 3, hit->color);
  return true;
}

template <bool kAnyHit>
bool World::traverse(const float o[3], const float d[3], float tmax, Hit* hit) const {
  // The part of the ray inside the object slab z in [0, max_height] and the grid's XY square.
  float t0 = 1e-4f, t1 = tmax;
  if (std::fabs(d[2]) > 1e-9f) {
    float ta = (0.f - o[2]) / d[2], tb = (max_height_ - o[2]) / d[2];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  } else if (o[2] < 0 || o[2] > max_height_) {
    return false;
  }
  for (int a = 0; a < 2; ++a) {
    if (std::fabs(d[a]) < 1e-9f) {
      if (o[a] < -extent_ || o[a] > extent_) return false;
      continue;
    }
    float ta = (-extent_ - o[a]) / d[a], tb = (extent_ - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 >= t1) return false;
  // 2D DDA over the cells the segment [t0, t1] crosses.
  const float px = o[0] + t0 * d[0] + extent_, py = o[1] + t0 * d[1] + extent_;
  int cx = std::min(cells_per_side_ - 1, std::max(0, static_cast<int>(px / cell_)));
  int cy = std::min(cells_per_side_ - 1, std::max(0, static_cast<int>(py / cell_)));
  const int step_x = d[0] > 0 ? 1 : -1, step_y = d[1] > 0 ? 1 : -1;
  const float inv_x = std::fabs(d[0]) > 1e-9f ? 1.f / d[0] : kInf;
  const float inv_y = std::fabs(d[1]) > 1e-9f ? 1.f / d[1] : kInf;
  float next_x = std::fabs(d[0]) > 1e-9f
                     ? ((cx + (step_x > 0 ? 1 : 0)) * cell_ - extent_ - o[0]) * inv_x
                     : kInf;
  float next_y = std::fabs(d[1]) > 1e-9f
                     ? ((cy + (step_y > 0 ? 1 : 0)) * cell_ - extent_ - o[1]) * inv_y
                     : kInf;
  const float dt_x = cell_ * std::fabs(inv_x), dt_y = cell_ * std::fabs(inv_y);
  float best = t1;
  bool found = false;
  Hit candidate;
  while (true) {
    const int cell = cy * cells_per_side_ + cx;
    for (int k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
      if (intersectObject(cell_items_[k], o, d, 1e-4f, best, &candidate)) {
        if (kAnyHit) return true;
        best = candidate.t;
        *hit = candidate;
        found = true;
      }
    }
    const float cell_exit = std::min(next_x, next_y);
    if (found && best <= cell_exit) return true;
    if (cell_exit >= t1) return found;
    if (next_x < next_y) {
      cx += step_x;
      next_x += dt_x;
    } else {
      cy += step_y;
      next_y += dt_y;
    }
    if (cx < 0 || cy < 0 || cx >= cells_per_side_ || cy >= cells_per_side_) return found;
  }
}

bool World::trace(const float origin[3], const float dir[3], float tmax, Hit* hit) const {
  float t_ground = kInf;
  if (dir[2] < -1e-9f && origin[2] > 0) t_ground = -origin[2] / dir[2];
  const float limit = std::min(tmax, t_ground);
  if (traverse<false>(origin, dir, limit, hit)) return true;
  if (t_ground > tmax) return false;
  hit->t = t_ground;
  for (int a = 0; a < 3; ++a) hit->p[a] = origin[a] + t_ground * dir[a];
  hit->p[2] = 0.f;
  hit->n[0] = hit->n[1] = 0;
  hit->n[2] = 1;
  hit->object = -1;
  const GroundSample g = ground(hit->p[0], hit->p[1]);
  hit->cls = g.cls;
  hit->material = g.material;
  std::copy(g.color, g.color + 3, hit->color);
  return true;
}

bool World::occluded(const float origin[3], const float dir[3], float tmax) const {
  Hit unused;
  return traverse<true>(origin, dir, tmax, &unused);
}

namespace {

// Distance from p to the surface of an object (boxes exact; ellipsoids along the centre ray).
float surfaceDistance(const Object& ob, const float p[3]) {
  if (ob.shape == Object::kBox) {
    float outside2 = 0, inside = std::numeric_limits<float>::max();
    bool in = true;
    for (int k = 0; k < 3; ++k) {
      const float below = ob.lo[k] - p[k], above = p[k] - ob.hi[k];
      const float d = std::max(below, above);
      if (d > 0) {
        outside2 += d * d;
        in = false;
      } else {
        inside = std::min(inside, -d);
      }
    }
    return in ? inside : std::sqrt(outside2);
  }
  float u2 = 0, r2 = 0;
  float min_radius = std::numeric_limits<float>::max();
  for (int k = 0; k < 3; ++k) {
    const float c = 0.5f * (ob.lo[k] + ob.hi[k]), a = std::max(1e-6f, 0.5f * (ob.hi[k] - ob.lo[k]));
    const float d = p[k] - c;
    u2 += (d / a) * (d / a);
    r2 += d * d;
    min_radius = std::min(min_radius, a);
  }
  const float u = std::sqrt(u2);
  if (u < 1e-6f) return min_radius;
  return std::fabs(1.f - 1.f / u) * std::sqrt(r2);
}

}  // namespace

NearestSurface World::nearestSurface(const float p[3]) const {
  NearestSurface best;
  best.distance = std::fabs(p[2]);
  best.cls = ground(p[0], p[1]).cls;
  best.object = -1;
  // Objects whose cells lie within the current best distance of p (the grid covers the labelled
  // area; objects outside it are not listed and not considered).
  const float r = best.distance;
  const auto cellOf = [&](float v) {
    return std::min(cells_per_side_ - 1,
                    std::max(0, static_cast<int>(std::floor((v + extent_) / cell_))));
  };
  if (p[0] + r < -extent_ || p[0] - r > extent_ || p[1] + r < -extent_ || p[1] - r > extent_) {
    return best;
  }
  const int x0 = cellOf(p[0] - r), x1 = cellOf(p[0] + r);
  const int y0 = cellOf(p[1] - r), y1 = cellOf(p[1] + r);
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const int cell = y * cells_per_side_ + x;
      for (int k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
        const int index = cell_items_[k];
        const float d = surfaceDistance(objects_[index], p);
        if (d < best.distance) {
          best.distance = d;
          best.cls = objects_[index].cls;
          best.object = index;
        }
      }
    }
  }
  return best;
}

GroundSample World::ground(float x, float y) const {
  GroundSample g;
  if (std::fabs(x) > extent_ || std::fabs(y) > extent_) {
    const float n = valueNoise(x / 40.f, y / 40.f, seed_ + 99);
    g.cls = 255;
    g.material = Material::kOutside;
    setColor(g.color, 0.42f + 0.1f * n, 0.45f + 0.08f * n, 0.33f);
    return g;
  }
  auto set = [&](std::uint8_t cls, Material m, float r, float gg, float b) {
    g.cls = cls;
    g.material = m;
    setColor(g.color, r, gg, b);
  };
  switch (kind_) {
    case SceneKind::kCity: {
      const float dx = distanceToGrid(x, block_), dy = distanceToGrid(y, block_);
      const float d = std::min(dx, dy);
      if (d < road_half_) {
        // Dashed centre line along the road.
        const float along = dx < dy ? y : x;
        const bool marking = d < 0.15f && std::fmod(std::fabs(along), 6.f) < 3.f &&
                             std::max(dx, dy) > road_half_ + 3;
        if (marking) {
          set(1, Material::kMarking, 0.85f, 0.85f, 0.82f);
        } else {
          set(1, Material::kAsphalt, 0.3f, 0.3f, 0.32f);
        }
      } else if (d < road_half_ + 3.f) {
        set(5, Material::kPaving, 0.52f, 0.5f, 0.48f);
      } else {
        const int bx = static_cast<int>(std::floor(x / block_)),
                  by = static_cast<int>(std::floor(y / block_));
        const float type = hash01(seed_, 11, bx + 100, by + 100);
        if (type >= 0.62f && type < 0.85f) {
          set(3, Material::kGrass, 0.33f, 0.5f, 0.22f);
        } else if (type < 0.62f && hash01(seed_, 12, bx + 100, by + 100) < 0.3f) {
          set(3, Material::kGrass, 0.35f, 0.52f, 0.24f);  // lawns between buildings
        } else {
          set(5, Material::kPaving, 0.56f, 0.54f, 0.5f);
        }
      }
      break;
    }
    case SceneKind::kCountry: {
      const float ry = 12.f * std::sin(x / 30.f + seed_) + 15.f;
      const float rx = river_x_ + 10.f * std::sin(y / 22.f + 2.f * seed_);
      if (std::fabs(x - rx) < 7.f) {
        set(6, Material::kWater, 0.1f, 0.2f, 0.26f);
      } else if (std::fabs(y - ry) < 3.f) {
        set(2, Material::kAsphalt, 0.36f, 0.35f, 0.34f);
      } else {
        // Fields on a rotated grid.
        const float c = std::cos(0.2f), s = std::sin(0.2f);
        const float u = c * x + s * y, v = -s * x + c * y;
        const int fi = static_cast<int>(std::floor(u / 45.f)),
                  fj = static_cast<int>(std::floor(v / 35.f));
        const float type = hash01(seed_, 31, fi + 100, fj + 100);
        const float tone = hash01(seed_, 32, fi + 100, fj + 100);
        const float soil_patch = valueNoise(x / 18.f, y / 18.f, seed_ + 5);
        if (type < 0.58f) {
          if (tone < 0.4f) {
            set(0, Material::kField, 0.72f, 0.62f, 0.3f);  // ripe grain
          } else if (tone < 0.75f) {
            set(0, Material::kField, 0.4f, 0.55f, 0.2f);  // green crop, close to grass
          } else {
            set(0, Material::kField, 0.55f, 0.42f, 0.28f);  // ploughed, close to soil
          }
        } else if (type < 0.85f || soil_patch < 0.6f) {
          set(4, Material::kGrass, 0.36f, 0.52f, 0.24f);
        } else {
          set(5, Material::kSoil, 0.47f, 0.36f, 0.25f);
        }
      }
      break;
    }
    case SceneKind::kPort: {
      if (y < quay_y_) {
        set(0, Material::kWater, 0.09f, 0.17f, 0.22f);
      } else if (y < quay_y_ + 20.f) {
        // Quay apron with a road along it.
        if (std::fabs(y - (quay_y_ + 20.f - road_half_)) < road_half_) {
          set(5, Material::kAsphalt, 0.3f, 0.3f, 0.31f);
        } else {
          set(6, Material::kConcrete, 0.6f, 0.59f, 0.56f);
        }
      } else {
        const float dx = distanceToGrid(x + extent_, block_);
        const float dy = distanceToGrid(y - (quay_y_ + 24.f), block_);
        if (std::min(dx, dy) < road_half_) {
          set(5, Material::kAsphalt, 0.31f, 0.31f, 0.32f);
        } else {
          set(6, Material::kConcrete, 0.58f, 0.57f, 0.54f);
        }
      }
      break;
    }
  }
  return g;
}

std::vector<ObjectFootprint> groundFootprints(const World& world, std::uint8_t cls) {
  std::vector<ObjectFootprint> out;
  const auto& objects = world.objects();
  for (std::size_t i = 0; i < objects.size(); ++i) {
    const Object& o = objects[i];
    if (o.cls != cls || o.lo[2] > 0.01f) continue;
    const float cx = 0.5f * (o.lo[0] + o.hi[0]), cy = 0.5f * (o.lo[1] + o.hi[1]);
    if (std::fabs(cx) > world.extent() || std::fabs(cy) > world.extent()) continue;
    out.push_back({static_cast<int>(i), o.lo[0], o.lo[1], o.hi[0], o.hi[1]});
  }
  return out;
}

}  // namespace synth
}  // namespace sadsplat
