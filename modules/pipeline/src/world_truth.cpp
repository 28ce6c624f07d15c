#include "sadsplat/pipeline/world_truth.h"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "sadsplat/common/error.h"
#include "sadsplat/geo/map_frame.h"
#include "sadsplat/geo/raster_files.h"
#include "sadsplat/geo/vector_files.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/synth/aerial_benchmark.h"

namespace sadsplat {
namespace pipeline {

std::string writeWorldTruth(const std::string& world_id, const std::string& dir) {
  const std::optional<synth::World> world = synth::worldFromId(world_id);
  if (!world) throw Error("<synth>", "world", "a synth:KIND:SEED:TILES world id", world_id);
  const std::string wkt = geo::localMapFrame({0, 0, 1}).wkt;
  const auto& classes = world->classes();
  // The true DSM: the height of the topmost surface at each 0.25 m cell centre (ortho_truth's
  // grid), nodata outside the labelled area.
  const synth::OrthoTruth t = synth::orthoTruth(*world, 0.25);
  geo::Raster dsm = geo::Raster::floatsOf(t.width, t.height);
  dsm.nodata = -9999;
  for (std::size_t i = 0; i < t.heights.size(); ++i) {
    dsm.floats[i] = std::isfinite(t.heights[i]) && t.classes[i] != 255 ? t.heights[i] : -9999.f;
  }
  const geo::MapGrid grid{t.x0, t.y0, t.gsd, wkt};
  geo::writeGeoTiff(dir + "/truth_dsm.tif", dsm, &grid);
  // The buildings: one footprint per standing object of the class "building" (id = the object's
  // index in the world, as the surface samples' instance).
  std::vector<geo::LabelledPolygon> buildings;
  for (std::size_t c = 0; c < classes.size(); ++c) {
    if (classes[c].name != "building") continue;
    for (const synth::ObjectFootprint& f :
         synth::groundFootprints(*world, static_cast<std::uint8_t>(c))) {
      geo::LabelledPolygon p;
      p.ring = {{f.x0, f.y0}, {f.x1, f.y0}, {f.x1, f.y1}, {f.x0, f.y1}};
      p.id = f.object;
      p.class_name = classes[c].name;
      p.height = world->objects()[static_cast<std::size_t>(f.object)].hi[2];
      buildings.push_back(p);
    }
  }
  geo::writeLabelledPolygons(dir + "/truth_buildings.gpkg", "buildings", wkt, buildings);
  // The top surface every 0.5 m, traced straight down: position, class, instance (the object's
  // index; -1 = the ground).
  const float spacing = 0.5f, e = world->extent();
  const float down[3] = {0.f, 0.f, -1.f};
  std::ostringstream body;
  std::size_t samples = 0;
  for (float y = -e + spacing / 2; y < e; y += spacing) {
    for (float x = -e + spacing / 2; x < e; x += spacing) {
      const float top[3] = {x, y, world->maxHeight() + 10.f};
      synth::Hit hit;
      if (!world->trace(top, down, 1e5f, &hit) || hit.cls == 255) continue;
      char line[96];
      std::snprintf(line, sizeof line, "%.3f %.3f %.3f %d %d\n", hit.p[0], hit.p[1], hit.p[2],
                    int(hit.cls), hit.object);
      body << line;
      ++samples;
    }
  }
  io::writeFileAtomically(dir + "/truth_surface.ply", [&](std::ostream& out) {
    out << "ply\nformat ascii 1.0\ncomment sadsplat synth truth: " << world_id
        << ", top surface every " << spacing << " m; class = class id (classes.json), "
        << "instance = object index (-1 = ground)\nelement vertex " << samples
        << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar class\n"
        << "property int instance\nend_header\n"
        << body.str();
  });
  std::ostringstream s;
  s << "truth: truth_dsm.tif " << t.width << "x" << t.height << " at " << t.gsd << " m, "
    << buildings.size() << " building footprints, " << samples << " surface samples\n";
  return s.str();
}

}  // namespace pipeline
}  // namespace sadsplat
