// `sadsplat ortho`: the model on a map grid.
#include "sadsplat/pipeline/map_products.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "map_layers.h"
#include "sadsplat/common/error.h"
#include "sadsplat/geo/las_export.h"
#include "sadsplat/geo/map_frame.h"
#include "sadsplat/geo/raster_files.h"
#include "sadsplat/geo/vector_files.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/output_set.h"
#include "sadsplat/pipeline/labelled_cloud.h"
#include "sadsplat/pipeline/opened_run.h"
#include "sadsplat/pipeline/ortho_render.h"

namespace sadsplat {
namespace pipeline {
namespace {

using Vec3 = std::array<double, 3>;

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

struct ObjectCloudCounts {
  std::size_t files = 0, gaussians = 0;
};

// OUT/objects/ (OrthoRunOptions::object_clouds): each map object's Gaussians as
// object_<id>.pcd (the model's frame, every field) and object_<id>.las (the map's CRS), and
// objects.csv.
ObjectCloudCounts writeObjectClouds(const std::string& dir,
                                    const pcl::PointCloud<GaussianPoint>& cloud,
                                    const io::Scene& scene, const OrthoGrid& grid,
                                    const ClassObjects& objects, double min_opacity) {
  const std::vector<std::vector<std::size_t>> groups =
      objectGaussians(cloud, grid, objects, min_opacity);
  io::makeDirectory(dir);
  ObjectCloudCounts counts;
  geo::LasExportOptions las;
  las.classes = scene.classes;
  las.georeference = scene.georeference;
  las.local_frame = grid.frame;
  std::ostringstream csv;
  csv << "object_id,class_id,class,gaussians,centroid_x,centroid_y,centroid_z,map_x,map_y,"
         "height_m,file,las_file\n"
      << std::setprecision(12);  // UTM northings to 0.01 mm
  for (std::size_t k = 0; k < groups.size(); ++k) {
    const geo::MapObjectAttributes& a = objects.objects[k];
    csv << k + 1 << "," << a.class_id << "," << scene.classes[a.class_id].name << ","
        << groups[k].size() << ",";
    if (groups[k].empty()) {
      csv << ",,,,," << a.height << ",,\n";
      continue;
    }
    pcl::PointCloud<GaussianPoint> part;
    std::array<double, 3> sum{0, 0, 0};
    for (const std::size_t g : groups[k]) {
      part.push_back(cloud[g]);
      sum[0] += cloud[g].x, sum[1] += cloud[g].y, sum[2] += cloud[g].z;
    }
    const double n = static_cast<double>(groups[k].size());
    const std::array<double, 3> c{sum[0] / n, sum[1] / n, sum[2] / n};
    const std::array<double, 3> m = grid.frame.toMap(c);
    const std::string file = "object_" + std::to_string(k + 1);
    io::writeGaussians(dir + "/" + file + ".pcd", part);
    geo::writeGaussiansLas(dir + "/" + file + ".las", part, las);
    csv << c[0] << "," << c[1] << "," << c[2] << "," << m[0] << "," << m[1] << "," << a.height
        << "," << file << ".pcd," << file << ".las\n";
    ++counts.files;
    counts.gaussians += groups[k].size();
  }
  io::writeTextFileAtomically(dir + "/objects.csv", csv.str());
  return counts;
}

double roundToSignificant(double v, int digits) {
  const double p = std::pow(10.0, digits - 1 - std::floor(std::log10(v)));
  return std::round(v * p) / p;
}

}  // namespace

std::string orthoRun(const OrthoRunOptions& o) {
  if (o.gsd && !(*o.gsd > 0 && std::isfinite(*o.gsd))) {
    throw Error("<ortho>", "--gsd", "a ground sample distance > 0 (metres per pixel)",
                std::to_string(*o.gsd));
  }
  OrthoRenderOptions render_options = checkedRenderOptions(o, "<ortho>");
  if (!geo::haveGdal()) {
    throw Error("<ortho>", "build", "a sadsplat build with GDAL (Debian: libgdal-dev)",
                "a build without it");
  }
  // Written as a set: a failure leaves the previous set whole, a rerun replaces all of it.
  std::vector<std::string> outputs = {
      "orthophoto.tif", "orthophoto.png", "classes.tif", "classes.png", "confidence.tif",
      "confidence.png", "dsm.tif",        "dsm.png",     "classes.csv", "ortho.json"};
  if (o.object_clouds && o.vectors.empty()) {
    throw Error("<ortho>", "--object-clouds", "--vectors CLASSES (the objects' classes)",
                "no --vectors");
  }
  if (!(o.object_min_opacity >= 0 && o.object_min_opacity < 1)) {
    throw Error("<ortho>", "--object-min-opacity", "an opacity in [0, 1)",
                std::to_string(o.object_min_opacity));
  }
  if (!o.vectors.empty()) outputs.push_back("vectors.gpkg");
  if (o.object_clouds) outputs.push_back("objects");
  io::OutputSet files(o.out, outputs);
  OpenedRun run = openRun(o.run);
  // The classes of --vectors, checked before the render.
  std::vector<std::string> names;
  for (const ClassInfo& c : run.scene.classes) names.push_back(c.name);
  if (!o.vectors.empty() && run.trainer->numClasses() == 0) {
    throw Error("<ortho>", "--vectors", "a semantic model (classes)", "no classes");
  }
  const std::vector<int> vector_classes =
      classIdsOf(o.vectors, run.scene.classes, "<ortho>", "--vectors");
  const double gsd = o.gsd ? *o.gsd : roundToSignificant(photoGsd(run), 2);
  const OrthoGrid grid = footprintGrid(*run.trainer, run.scene, gsd, o.bounds);
  if (o.progress) {
    *o.progress << "ortho: " << grid.width << " x " << grid.height << " pixels at " << gsd << " m, "
                << grid.frame.crs_name << "\n";
  }
  render_options.cameras = trainingCameras(run.scene);
  pcl::PointCloud<GaussianPoint> labelled =
      setGaussianClasses(render_options, o, *run.trainer, run.scene, "<ortho>");
  const OrthoImages img = renderOrtho(*run.trainer, grid, render_options, o.progress);
  const std::size_t n = static_cast<std::size_t>(img.width) * img.height;
  geo::MapGrid map{grid.x0, grid.y0, grid.gsd, grid.frame.wkt};

  geo::Raster photo = geo::Raster::bytesOf(img.width, img.height, 4);
  photo.last_band_is_alpha = true;
  for (std::size_t i = 0; i < n; ++i) {
    for (int c = 0; c < 3; ++c) photo.bytes[4 * i + c] = img.rgb[3 * i + c];
    photo.bytes[4 * i + 3] = img.covered[i] ? 255 : 0;
  }
  geo::writeGeoTiff(files.path("orthophoto.tif"), photo, &map);
  geo::writePng(files.path("orthophoto.png"), photo);

  const auto& classes = run.scene.classes;
  const bool semantic = run.trainer->numClasses() > 0;
  std::vector<std::int64_t> pixels(classes.size(), 0);
  std::int64_t covered = 0;
  for (std::size_t i = 0; i < n; ++i) {
    covered += img.covered[i];
    if (img.classes[i] < classes.size()) ++pixels[img.classes[i]];
  }
  std::size_t polygons = 0;
  ObjectCloudCounts clouds;
  if (semantic) {
    geo::Raster ids = geo::Raster::bytesOf(img.width, img.height, 1);
    ids.bytes = img.classes;
    ids.nodata = 255;
    for (const ClassInfo& c : classes) ids.palette.push_back(c.color);
    geo::writeGeoTiff(files.path("classes.tif"), ids, &map);
    if (!o.vectors.empty()) {
      geo::ObjectPolygonOptions v;
      v.simplify = grid.gsd;
      v.min_area = 4 * grid.gsd * grid.gsd;
      const ClassObjects objects =
          classObjects(img, vector_classes, o.object_step, minObjectCells(gsd));
      polygons = geo::writeObjectPolygons(files.path("vectors.gpkg"), objects.labels, img.width,
                                          img.height, objects.objects, map, names, v);
      if (o.object_clouds) {
        if (labelled.empty()) labelled = labelledCloud(*run.trainer, run.scene, o.progress);
        clouds = writeObjectClouds(files.path("objects"), labelled, run.scene, grid, objects,
                                   o.object_min_opacity);
      }
    }
    geo::Raster preview = geo::Raster::bytesOf(img.width, img.height, 4);
    preview.last_band_is_alpha = true;
    for (std::size_t i = 0; i < n; ++i) {
      if (img.classes[i] >= classes.size()) continue;
      for (int c = 0; c < 3; ++c) preview.bytes[4 * i + c] = classes[img.classes[i]].color[c];
      preview.bytes[4 * i + 3] = 255;
    }
    geo::writePng(files.path("classes.png"), preview);
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
    geo::writeGeoTiff(files.path("confidence.tif"), conf, &map);
    geo::writePng(files.path("confidence.png"), conf_preview);
  }
  geo::Raster dsm = geo::Raster::floatsOf(img.width, img.height);
  dsm.nodata = -9999;
  std::vector<float> heights;
  for (std::size_t i = 0; i < n; ++i) {
    dsm.floats[i] = img.covered[i] ? img.elevation[i] : -9999.f;
    if (img.covered[i]) heights.push_back(img.elevation[i]);
  }
  geo::writeGeoTiff(files.path("dsm.tif"), dsm, &map);
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
  geo::writePng(files.path("dsm.png"), dsm_preview);

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
  io::writeTextFileAtomically(files.path("classes.csv"), csv.str());

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
  j["few_views_share"] = n ? double(img.few_views) / n : 0.0;
  addRenderOptions(j, o, img, run.scene.classes);
  j["map_scale_factor"] = grid.frame.k;
  j["grid_convergence_degrees"] = std::atan2(grid.frame.s, grid.frame.c) * 180 / M_PI;
  j["similarity_fit_residual_m"] = grid.frame.fit_residual;
  if (run.scene.georeference && !run.scene.georeference->up_source.empty()) {
    // The frame's accuracy statement, as sfm measured it (georeference.json).
    const io::Georeference& g = *run.scene.georeference;
    nlohmann::json a = {{"source", g.up_source},
                        {"horizontal_rms_m", g.horizontal_rms_metres},
                        {"vertical_rms_m", g.vertical_rms_metres},
                        {"doubts", g.doubts}};
    if (g.check_points > 0) {
      a["check_points"] = g.check_points;
      a["check_rmse_horizontal_m"] = g.check_rmse_horizontal;
      a["check_rmse_vertical_m"] = g.check_rmse_vertical;
    }
    j["georeference_accuracy"] = a;
  }
  j["height_datum"] = grid.frame.georeferenced
                          ? "the photos' GPS altitude reference (origin altitude + local up)"
                          : "the scene frame's up axis";
  if (!o.vectors.empty()) {
    j["vectors"] = {{"file", "vectors.gpkg"},
                    {"polygons", polygons},
                    {"object_step_m", o.object_step},
                    {"merged_under_m2", kMinObjectM2}};
  }
  if (o.object_clouds) {
    j["object_clouds"] = {
        {"folder", "objects"},
        {"files", clouds.files},
        {"formats",
         {{"pcd", "the model's frame, every Gaussian field"},
          {"las", "the map's CRS, centres with base colour and ASPRS class"}}},
        {"gaussians", clouds.gaussians},
        {"min_opacity", o.object_min_opacity},
        {"labels", "the class the training views render where the Gaussian draws"}};
  }
  j["files"] = semantic ? nlohmann::json{"orthophoto.tif", "classes.tif", "dsm.tif",
                                         "confidence.tif", "classes.csv"}
                        : nlohmann::json{"orthophoto.tif", "dsm.tif", "classes.csv"};
  io::writeTextFileAtomically(files.path("ortho.json"), j.dump(2) + "\n");
  files.commit();

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
  if (!o.vectors.empty()) {
    s << "  vectors.gpkg: " << polygons << " polygons of ";
    for (std::size_t k = 0; k < o.vectors.size(); ++k) s << (k ? ", " : "") << o.vectors[k];
    s << std::setprecision(2) << std::defaultfloat;
    if (o.object_step > 0) {
      s << " (regions cut where the DSM steps by more than " << o.object_step << ")\n";
    } else {
      s << " (plain regions)\n";
    }
  }
  if (o.object_clouds) {
    s << "  objects/: " << clouds.files << " object clouds as .pcd and .las (" << clouds.gaussians
      << " Gaussians), objects.csv\n";
  }
  return s.str();
}

}  // namespace pipeline
}  // namespace sadsplat
