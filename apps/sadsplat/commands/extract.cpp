// `sadsplat extract MODEL --class NAME --out FILE`: the Gaussians (or points) of one class.
#include <iostream>

#include "commands.h"
#include "sadsplat/common/error.h"
#include "sadsplat/common/semantic_cloud.h"
#include "sadsplat/filters/class_extraction.h"
#include "sadsplat/geo/las_export.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/run_directory.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/io/scene_import.h"
#include "sadsplat/pipeline/labelled_cloud.h"
#include "sadsplat/pipeline/las_frame.h"
#include "sadsplat/pipeline/raised_gaussians.h"

namespace sadsplat {
namespace cli {
namespace {

// The points of one class (or of all others) of a cloud, read and written with the given
// functions.
template <typename PointT, typename Read, typename Write>
void extractClass(const std::string& in, const std::string& out, std::uint32_t class_id,
                  bool negative, Read read, Write write) {
  const auto cloud = std::make_shared<pcl::PointCloud<PointT>>(read(in));
  filters::ClassExtraction<PointT> filter;
  filter.setClassId(class_id);
  filter.setNegative(negative);
  filter.setInputCloud(cloud);
  pcl::PointCloud<PointT> kept;
  filter.filter(kept);
  write(out, kept);
  std::cout << "kept " << kept.size() << " of " << cloud->size() << " points\n";
}

class ExtractCommand : public Command {
 public:
  CLI::App* add(CLI::App& app) override {
    CLI::App* c = app.add_subcommand("extract", "Write the Gaussians of one class");
    c->add_option("MODEL", in_, "input .ply / .pcd, or a run directory")->required();
    c->add_option("--class", class_, "class name (or id)")->required();
    c->add_option("--classes", classes_, "classes.json or scene cache naming classes");
    c->add_option("--out", out_, "output .ply, .pcd or .las")->required();
    c->add_option("--classification-map", classification_map_,
                  ".las: JSON {\"class name\": ASPRS code} replacing the default codes");
    c->add_flag("--negative", negative_, "keep every class except this one");
    c->add_option("--on-surface", on_surface_,
                  "a run directory only: keep only the Gaussians at most this far (scene units, "
                  "metres for georeferenced or synth scenes) from the surface (median depth) the "
                  "training views render where they see it: floaters and Gaussians inside "
                  "volumes go");
    c->add_option("--raised-check", raised_check_,
                  "a run directory only: leave out the Gaussians of a raised class (median at "
                  "least 2.5 m above the ground: buildings, trees) lower than this share of "
                  "their class's median height above the ground (0.33 as `ortho`'s; metres: "
                  "georeferenced or synth scenes), e.g. building Gaussians on the street that "
                  "join two buildings into one object; 0 = off (default)");
    return c;
  }

  int run(const Invocation&) override {
    std::string in = in_, classes = classes_;
    if (raised_check_ != 0 && !io::isDirectory(in)) {
      throw Error(in, "--raised-check", "a run directory (its scene gives the up direction)",
                  "a file");
    }
    if (!(raised_check_ >= 0 && raised_check_ <= 1)) {
      throw Error("<command line>", "--raised-check", "a share in [0, 1]",
                  std::to_string(raised_check_));
    }
    if (on_surface_ != 0 && !io::isDirectory(in)) {
      throw Error(in, "--on-surface",
                  "a run directory (the check renders its model through its training views)",
                  "a file");
    }
    if (io::isDirectory(in)) {  // a run directory: its model and its class list
      const io::RunDirectory run(in);
      if (classes.empty()) {
        classes = run.classes();
        if (!io::pathExists(classes) && io::pathExists(run.runJson())) {
          throw Error(classes, "file", "a run trained with classes",
                      "none (its scene had no classes.json: the model has no classes to extract)");
        }
      }
      in = run.model();
    }
    const std::uint32_t id = classId(classes);
    const bool las = io::lowerExtension(out_) == ".las";
    geo::LasExportOptions las_options;
    if (las) {
      las_options = pipeline::lasOptionsForModel(in, classification_map_, &std::cerr);
      if (!classes.empty()) {
        las_options.classes = io::isSceneCache(classes) ? io::readSceneCache(classes).classes
                                                        : io::readClassesJson(classes);
      }
    }
    if (io::cloudKind(in) == io::CloudKind::kSemantic) {
      extractClass<pcl::PointXYZRGBL>(
          in, out_, id, negative_, io::readSemanticCloud,
          [&](const std::string& p, const pcl::PointCloud<pcl::PointXYZRGBL>& c) {
            if (las) {
              std::cout << geo::writeSemanticLas(p, c, las_options) << "\n";
            } else {
              io::writeSemanticCloud(p, c);
            }
          });
    } else {
      const auto read = [&](const std::string& p) {
        pcl::PointCloud<GaussianPoint> model = io::readGaussians(p);
        if (on_surface_ != 0) {
          model =
              pipeline::gaussiansOnSurface(in_, model, static_cast<float>(on_surface_), &std::cerr);
          std::cout << "on the surface (within " << on_surface_ << "): " << model.size()
                    << " Gaussians\n";
        }
        if (raised_check_ != 0) {
          pipeline::RaisedGaussianOptions options;
          options.share = raised_check_;
          model = pipeline::withoutLowRaisedGaussians(in_, model, options, &std::cout);
        }
        return model;
      };
      extractClass<GaussianPoint>(
          in, out_, id, negative_, read,
          [&](const std::string& p, const pcl::PointCloud<GaussianPoint>& c) {
            if (las) {
              std::cout << geo::writeGaussiansLas(p, c, las_options) << "\n";
            } else {
              io::writeGaussians(p, c);
            }
          });
    }
    return 0;
  }

 private:
  std::uint32_t classId(const std::string& classes) const {
    if (classes.empty()) {
      std::size_t used = 0;
      unsigned long id = 0;
      try {
        id = std::stoul(class_, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != class_.size() || id >= kUnlabelled) {
        throw Error("<command line>", "--class", "a class id, or --classes FILE to use names",
                    class_);
      }
      return static_cast<std::uint32_t>(id);
    }
    const auto list = io::isSceneCache(classes) ? io::readSceneCache(classes).classes
                                                : io::readClassesJson(classes);
    filters::ClassExtraction<GaussianPoint> by_name;
    by_name.setClassName(class_, list);
    return by_name.getClassId();
  }

  std::string in_, out_, class_, classes_, classification_map_;
  bool negative_ = false;
  double on_surface_ = 0;
  double raised_check_ = 0;
};

}  // namespace

std::unique_ptr<Command> makeExtractCommand() { return std::make_unique<ExtractCommand>(); }

}  // namespace cli
}  // namespace sadsplat
