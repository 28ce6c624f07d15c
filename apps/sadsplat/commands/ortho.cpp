// `sadsplat ortho RUN --out DIR`: the map products of a trained run as GeoTIFF: true
// orthophoto, class map, surface model, confidence, and the area of every class.
#include <array>
#include <iostream>
#include <vector>

#include "commands.h"
#include "sadsplat/pipeline/map_products.h"

namespace sadsplat {
namespace cli {
namespace {

class OrthoCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand(
        "ortho",
        "Map products of a trained run: orthophoto, class map, surface model and confidence as "
        "GeoTIFF (UTM of the georeference, or local metres), class areas");
    c->add_option("RUN", o_.run, "run directory")->required();
    c->add_option("--out", o_.out, "output directory")->required();
    c->add_option("--gsd", gsd_, "metres per pixel (default: the photos' ground sample distance)");
    c->add_option("--bounds", bounds_,
                  "xmin,ymin,xmax,ymax in the map's CRS (default: the "
                  "model's footprint)")
        ->delimiter(',')
        ->expected(4);
    c->add_option("--height", o_.height,
                  "the DSM's height: first = of the first surface the cell's vertical ray meets "
                  "(where the transmittance falls below 0.5); blend = the alpha-weighted mean "
                  "depth through every Gaussian on the ray")
        ->default_val("first");
    c->add_option("--class-from", o_.class_from,
                  "the class map's class: blend = of the feature composited along the ray; "
                  "first = of the Gaussians in front of the first surface; views = the class "
                  "with the most blending weight along the ray, each Gaussian counted as the "
                  "class the training views give it (as model.ply's labels)")
        ->default_val("views");
    c->add_option("--min-views", o_.min_views,
                  "cells whose surface fewer training photos see unoccluded are nodata (default 0: "
                  "keep all)")
        ->default_val(0);
    c->add_option("--depth-tolerance", o_.depth_tolerance,
                  "--min-views: a photo sees a cell when the depth it renders there agrees within "
                  "this share of the cell's depth")
        ->default_val(0.02);
    c->add_option("--min-spread", o_.min_spread,
                  "cells whose photos all look from one side (horizontal directions spread less "
                  "than this many degrees) are nodata too (default 0: off)")
        ->default_val(0);
    c->add_option("--on-surface", o_.on_surface,
                  "make the maps of the Gaussians at most this far (scene units) from the surface "
                  "the training photos render where they draw, as `extract --on-surface` "
                  "(default 0: all)")
        ->default_val(0);
    c->add_option("--raised-check", o_.raised_check,
                  "a cell of a raised class (one whose cells stand at a median >= 2.5 m above "
                  "the ground: buildings, trees) lower above the ground than this share of that "
                  "median takes the most likely ground class (0: off; skipped with a warning "
                  "where the DSM shows no ground)")
        ->default_val(0.33);
    c->add_option("--pit-depth", o_.pit_depth,
                  "a DSM cell of a ground class (roads, grass, water: classes whose cells stand "
                  "at a median below 1.25 m above the ground) more than this below the median "
                  "height of the ground classes around it takes that height: the surface fell "
                  "through thin ground Gaussians (map units; 0: off; skipped with --raised-check's "
                  "warning)")
        ->default_val(1.0);
    c->add_option("--spike-height", o_.spike_height,
                  "a DSM cell of a ground class more than this above the median height of the "
                  "ground classes around it takes that height, after --trim: a road shows the "
                  "ground, not a floater over it (map units; 0: off; skipped with "
                  "--raised-check's warning)")
        ->default_val(0.0);
    c->add_option("--spike-clearance", o_.spike_clearance,
                  "--spike-height spares the cells within this of a raised class's cell (a roof "
                  "cell the class map calls road or paved stands at the roof's height; map "
                  "units)")
        ->default_val(4.0);
    c->add_option("--ground-window", o_.ground_window,
                  "--raised-check, --pit-depth, --spike-height: the ground is a low percentile of "
                  "the DSM in windows of this side (map units)")
        ->default_val(20);
    c->add_option("--vectors", o_.vectors,
                  "classes (names, comma-separated) whose objects are also written as polygons "
                  "to OUT/vectors.gpkg (GeoPackage: object_id, class, height_m, area_m2; the "
                  "map's CRS)")
        ->delimiter(',');
    c->add_option("--object-step", o_.object_step,
                  "--vectors: a class's regions are cut into objects where the DSM steps by more "
                  "than this between neighbouring cells (neighbouring buildings of different "
                  "heights; map units; 0: the plain regions)")
        ->default_val(1.5);
    c->add_option("--trim", o_.trim,
                  "classes (names, comma-separated) whose objects on the map are trimmed to the "
                  "hull of their opaque Gaussians' centres: cells outside take the next most "
                  "likely class around them (a roof's spill over its walls); auto: building "
                  "where the model has it; none: off")
        ->delimiter(',')
        ->default_val("auto");
    c->add_option(
         "--trim-whole-under", o_.trim_whole_under,
         "--trim: objects with fewer opaque Gaussians of their class over them go whole (0: kept)")
        ->default_val(0);
    c->add_flag("--object-clouds", o_.object_clouds,
                "--vectors: also OUT/objects/: each object's Gaussians (its class, centre over the "
                "object) as object_<id>.pcd, ids as in vectors.gpkg, and objects.csv");
    c->add_option("--object-min-opacity", o_.object_min_opacity,
                  "--object-clouds: only Gaussians at least this opaque (0: all, as a splat "
                  "viewer draws the object)")
        ->default_val(0.5);
    return c;
  }
  int run(const Invocation&) override {
    if (gsd_set()) o_.gsd = gsd_;
    if (!bounds_.empty())
      o_.bounds = std::array<double, 4>{bounds_[0], bounds_[1], bounds_[2], bounds_[3]};
    o_.progress = &std::cout;
    std::cout << pipeline::orthoRun(o_);
    return 0;
  }

 private:
  bool gsd_set() const { return gsd_ != kUnset; }
  static constexpr double kUnset = -1e300;
  pipeline::OrthoRunOptions o_;
  double gsd_ = kUnset;
  std::vector<double> bounds_;
};

}  // namespace

std::unique_ptr<Command> makeOrthoCommand() { return std::make_unique<OrthoCommand>(); }

}  // namespace cli
}  // namespace sadsplat
