#pragma once
/// \file world.h
/// \brief A procedural aerial world: a labelled ground (analytic class layout) and solid objects
/// (boxes and ellipsoids) in a uniform XY grid, with ray casting. Units are metres, z is up.

#include <cstdint>
#include <string>
#include <vector>

#include "sadsplat/common/class_info.h"

namespace sadsplat {
namespace synth {

/// \brief The three scene kinds of the paper's 3D-AS data set.
enum class SceneKind { kCity, kCountry, kPort };

/// \brief "city", "country" or "port".
const char* sceneKindName(SceneKind kind);
/// \brief Parses a kind name; throws sadsplat::Error on anything else.
SceneKind parseSceneKind(const std::string& name);

/// \brief Surface materials: how a hit is textured and lit (several per class).
enum class Material : std::uint8_t {
  kAsphalt,
  kMarking,
  kPaving,
  kGrass,
  kFoliage,
  kRoof,
  kFlatRoof,
  kWall,
  kCarPaint,
  kField,
  kSoil,
  kWater,
  kHull,
  kDeck,
  kContainer,
  kSteel,
  kConcrete,
  kOutside
};

/// \brief One solid object.
struct Object {
  enum Shape : std::uint8_t { kBox, kEllipsoid } shape = kBox;
  float lo[3] = {0, 0, 0};  ///< axis-aligned bounds (the ellipsoid fills them)
  float hi[3] = {0, 0, 0};
  std::uint8_t cls = 0;             ///< class id
  Material top = Material::kRoof;   ///< material of faces whose normal points up
  Material side = Material::kWall;  ///< material of the other faces
  float color[3] = {1, 1, 1};       ///< base colour (0..1)
};

/// \brief A ray-surface intersection.
struct Hit {
  float t = 0;  ///< distance along the (unit) ray
  float p[3] = {0, 0, 0};
  float n[3] = {0, 0, 1};
  int object = -1;       ///< index into World::objects, -1 = ground
  std::uint8_t cls = 0;  ///< class id, 255 = outside the labelled area
  Material material = Material::kOutside;
  float color[3] = {0, 0, 0};  ///< base colour before texture and light
};

/// \brief The true surface nearest to a point (World::nearestSurface).
struct NearestSurface {
  float distance = 0;    ///< metres from the point to the surface
  std::uint8_t cls = 0;  ///< its class id, 255 = outside the labelled area
  int object = -1;       ///< index into World::objects (its instance), -1 = ground
};

/// \brief Ground class and base colour at a point of the z = 0 plane.
struct GroundSample {
  std::uint8_t cls = 255;
  Material material = Material::kOutside;
  float color[3] = {0.5f, 0.5f, 0.5f};
};

/// \brief A generated world. Deterministic in (kind, seed).
class World {
 public:
  /// \brief Builds the layout of `kind` from `seed`; a city can be `tiles` x `tiles` times the
  /// area (its block grid continues; tiles = 1 is the ordinary scene, unchanged).
  /// \throws sadsplat::Error for tiles > 1 on another kind or tiles outside [1, 8]
  World(SceneKind kind, std::uint64_t seed, int tiles = 1);

  SceneKind kind() const { return kind_; }
  /// \brief The labelled area is [-extent, extent]^2; outside it the ground is label 255.
  float extent() const { return extent_; }
  /// \brief The extent of a world of `tiles` x `tiles` ordinary scenes (100 m per tile).
  static float extentOf(int tiles) { return 100.f * tiles; }
  int tiles() const { return tiles_; }
  float maxHeight() const { return max_height_; }
  const std::vector<ClassInfo>& classes() const { return classes_; }
  const std::vector<Object>& objects() const { return objects_; }

  /// \brief Nearest surface along a unit-direction ray within (0, tmax], or false (sky).
  bool trace(const float origin[3], const float dir[3], float tmax, Hit* hit) const;
  /// \brief Whether anything blocks the ray within (0, tmax] (shadow rays).
  bool occluded(const float origin[3], const float dir[3], float tmax) const;
  /// \brief The ground at (x, y).
  GroundSample ground(float x, float y) const;
  /// \brief The nearest true surface to `p`: the ground plane or an object's surface (a box's
  /// faces exactly; an ellipsoid's along the ray from its centre, exact for spheres). Faces that
  /// touch the ground (a box's bottom) count as surfaces too.
  NearestSurface nearestSurface(const float p[3]) const;

 private:
  void buildCity();
  void buildCountry();
  void buildPort();
  void buildGrid();
  void addBox(float x0, float y0, float z0, float x1, float y1, float z1, std::uint8_t cls,
              Material top, Material side, const float color[3]);
  void addTree(float x, float y, float radius, float height, std::uint8_t cls, float shade);
  bool intersectObject(int index, const float o[3], const float d[3], float tmin, float tmax,
                       Hit* hit) const;
  template <bool kAnyHit>
  bool traverse(const float o[3], const float d[3], float tmax, Hit* hit) const;

  SceneKind kind_;
  std::uint64_t seed_;
  int tiles_ = 1;
  float extent_ = 100.f;
  float max_height_ = 1.f;
  std::vector<ClassInfo> classes_;
  std::vector<Object> objects_;
  // Uniform XY grid over [-extent, extent]^2: cell (i, j) lists objects whose bounds overlap it.
  float cell_ = 4.f;
  int cells_per_side_ = 0;
  std::vector<int> cell_start_;  // CSR offsets, cells_per_side_^2 + 1
  std::vector<int> cell_items_;
  // Kind-specific layout parameters used by ground().
  float block_ = 40.f, road_half_ = 4.f, quay_y_ = 0.f, river_x_ = 0.f;
};

/// \brief The ground footprint of one true object: an axis-aligned rectangle on the ground.
struct ObjectFootprint {
  int object = -1;  ///< index into World::objects
  float x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

/// \brief The footprints of the objects of class `cls` that stand on the ground (their bottom at
/// z = 0; structures on top of them lie within their footprint and are not objects of their own)
/// and whose centre lies in the labelled area: the true buildings of a scene, one per object.
std::vector<ObjectFootprint> groundFootprints(const World& world, std::uint8_t cls);

/// \brief Deterministic hash of integers to [0, 1).
float hash01(std::uint64_t a, std::uint64_t b = 0, std::uint64_t c = 0, std::uint64_t d = 0);
/// \brief Smooth value noise in [0, 1) at (x, y), deterministic in `seed`.
float valueNoise(float x, float y, std::uint64_t seed);

}  // namespace synth
}  // namespace sadsplat
