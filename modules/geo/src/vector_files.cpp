#include "sadsplat/geo/vector_files.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"

#if SADSPLAT_HAVE_GDAL
#include <gdal_alg.h>
#include <ogr_api.h>
#include <ogr_geometry.h>
#include <ogr_spatialref.h>
#include <ogrsf_frmts.h>

#include "gdal_support.h"
#endif

namespace sadsplat {
namespace geo {

#if SADSPLAT_HAVE_GDAL

namespace {

// Writes one GeoPackage layer atomically: the layer in the CRS `wkt` (none when empty or not
// readable), its `fields`, then fill(layer) inside one transaction; returns what fill counted.
template <typename Fill>
std::size_t writeGeoPackageLayer(const std::string& path, const std::string& layer_name,
                                 const std::string& wkt, OGRwkbGeometryType geometry,
                                 const std::vector<std::pair<const char*, OGRFieldType>>& fields,
                                 Fill fill) {
  gdal::init();
  OGRSpatialReference srs;
  const bool has_srs = !wkt.empty() && srs.importFromWkt(wkt.c_str()) == OGRERR_NONE;
  if (has_srs) srs.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  std::size_t written = 0;
  io::writeViaTemporaryPath(path, [&](const std::string& tmp) {
    GDALDriver* gpkg = GetGDALDriverManager()->GetDriverByName("GPKG");
    if (!gpkg) gdal::failed(path, "GeoPackage driver");
    gdal::Dataset out(gpkg->Create(tmp.c_str(), 0, 0, 0, GDT_Unknown, nullptr));
    if (!out) gdal::failed(path, "create");
    OGRLayer* layer =
        out->CreateLayer(layer_name.c_str(), has_srs ? &srs : nullptr, geometry, nullptr);
    if (!layer) gdal::failed(path, "layer");
    for (const auto& [name, type] : fields) {
      OGRFieldDefn field(name, type);
      if (layer->CreateField(&field) != OGRERR_NONE) gdal::failed(path, "fields");
    }
    if (layer->StartTransaction() != OGRERR_NONE) gdal::failed(path, "transaction");
    written = fill(layer);
    if (layer->CommitTransaction() != OGRERR_NONE) gdal::failed(path, "transaction");
    CPLErrorReset();
    GDALClose(out.release());
    if (CPLGetLastErrorType() >= CE_Failure) gdal::failed(path, "close");
  });
  return written;
}

// The polygonal parts of `g` into `out` (a collection's members, recursively).
void addPolygons(const OGRGeometry* g, OGRMultiPolygon* out) {
  switch (wkbFlatten(g->getGeometryType())) {
    case wkbPolygon:
      out->addGeometry(g);
      break;
    case wkbMultiPolygon:
    case wkbGeometryCollection:
      for (const OGRGeometry* part : *g->toGeometryCollection()) addPolygons(part, out);
      break;
    default:  // points and lines MakeValid may leave where a region was one cell thin
      break;
  }
}

// OGC-valid polygons of `shape`: cells joined only at a corner polygonize into a ring that
// touches itself there, which GEOS (QGIS's processing, PostGIS) calls invalid; GEOS's MakeValid
// splits such rings, and the polygonal parts of what it returns are kept.
std::unique_ptr<OGRMultiPolygon> validPolygons(std::unique_ptr<OGRGeometry> shape) {
  CPLPushErrorHandler(CPLQuietErrorHandler);  // GEOS's notes on each invalid ring
  if (!shape->IsValid()) {
    std::unique_ptr<OGRGeometry> fixed(shape->MakeValid());
    if (fixed) shape = std::move(fixed);
  }
  CPLPopErrorHandler();
  auto out = std::make_unique<OGRMultiPolygon>();
  addPolygons(shape.get(), out.get());
  return out;
}

}  // namespace

std::size_t writeObjectPolygons(const std::string& path, const std::vector<int>& labels, int width,
                                int height, const std::vector<MapObjectAttributes>& objects,
                                const MapGrid& grid, const std::vector<std::string>& names,
                                const ObjectPolygonOptions& o) {
  if (width <= 0 || height <= 0 ||
      labels.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height)) {
    throw Error(path, "object labels", std::to_string(width) + " x " + std::to_string(height),
                std::to_string(labels.size()) + " cells");
  }
  std::vector<std::uint8_t> mask(labels.size(), 0);
  for (std::size_t i = 0; i < labels.size(); ++i) {
    if (labels[i] < 0 || static_cast<std::size_t>(labels[i]) > objects.size()) {
      throw Error(path, "object labels", "0 .. " + std::to_string(objects.size()),
                  std::to_string(labels[i]));
    }
    mask[i] = labels[i] > 0;
  }
  gdal::init();
  // The object ids and a mask of the cells with one, in memory.
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  gdal::Dataset raster(mem->Create("", width, height, 2, GDT_Int32, nullptr));
  if (!raster) gdal::failed(path, "polygonize");
  double transform[6] = {grid.x0, grid.gsd, 0, grid.y0, 0, -grid.gsd};
  raster->SetGeoTransform(transform);
  std::vector<std::int32_t> ids(labels.begin(), labels.end());
  std::vector<std::int32_t> selected(mask.begin(), mask.end());
  GDALRasterBand* id_band = raster->GetRasterBand(1);
  GDALRasterBand* mask_band = raster->GetRasterBand(2);
  if (id_band->RasterIO(GF_Write, 0, 0, width, height, ids.data(), width, height, GDT_Int32, 0, 0,
                        nullptr) != CE_None ||
      mask_band->RasterIO(GF_Write, 0, 0, width, height, selected.data(), width, height, GDT_Int32,
                          0, 0, nullptr) != CE_None) {
    gdal::failed(path, "polygonize");
  }
  // Polygonized into a memory layer first: then filtered, simplified and written.
  GDALDriver* memory = GetGDALDriverManager()->GetDriverByName("Memory");
  gdal::Dataset scratch(memory->Create("", 0, 0, 0, GDT_Unknown, nullptr));
  if (!scratch) gdal::failed(path, "polygonize");
  OGRLayer* raw = scratch->CreateLayer("raw", nullptr, wkbPolygon, nullptr);
  OGRFieldDefn id_field("object_id", OFTInteger);
  if (!raw || raw->CreateField(&id_field) != OGRERR_NONE) gdal::failed(path, "polygonize");
  char eight[] = "8CONNECTED=8";
  char* options[] = {eight, nullptr};
  if (GDALPolygonize(id_band, mask_band, raw, 0, options, nullptr, nullptr) != CE_None) {
    gdal::failed(path, "polygonize");
  }
  return writeGeoPackageLayer(
      path, o.layer, grid.wkt, wkbMultiPolygon,
      {{"object_id", OFTInteger},
       {"class_id", OFTInteger},
       {"class", OFTString},
       {"height_m", OFTReal},
       {"height_above_ground_m", OFTReal},
       {"area_m2", OFTReal}},
      [&](OGRLayer* layer) {
        std::size_t written = 0;
        raw->ResetReading();
        for (std::unique_ptr<OGRFeature> f(raw->GetNextFeature()); f;
             f.reset(raw->GetNextFeature())) {
          const OGRGeometry* g = f->GetGeometryRef();
          const int id = f->GetFieldAsInteger(0);
          if (!g || id <= 0) continue;
          std::unique_ptr<OGRGeometry> simplified(
              o.simplify > 0 ? g->SimplifyPreserveTopology(o.simplify) : g->clone());
          if (!simplified || simplified->IsEmpty()) continue;
          std::unique_ptr<OGRMultiPolygon> shape = validPolygons(std::move(simplified));
          if (shape->IsEmpty()) continue;
          const double a = shape->get_Area();
          if (a < o.min_area) continue;
          const MapObjectAttributes& object = objects[static_cast<std::size_t>(id) - 1];
          const int c = object.class_id;
          OGRFeature feature(layer->GetLayerDefn());
          feature.SetField("object_id", id);
          feature.SetField("class_id", c);
          feature.SetField("class", c >= 0 && c < static_cast<int>(names.size())
                                        ? names[static_cast<std::size_t>(c)].c_str()
                                        : "");
          feature.SetField("height_m", object.height);
          if (std::isfinite(object.height_above_ground)) {
            feature.SetField("height_above_ground_m", object.height_above_ground);
          } else {
            feature.SetFieldNull(feature.GetFieldIndex("height_above_ground_m"));
          }
          feature.SetField("area_m2", a);
          feature.SetGeometryDirectly(shape.release());
          if (layer->CreateFeature(&feature) != OGRERR_NONE) gdal::failed(path, "feature");
          ++written;
        }
        return written;
      });
}

std::size_t writeLabelledPolygons(const std::string& path, const std::string& layer_name,
                                  const std::string& wkt,
                                  const std::vector<LabelledPolygon>& polygons) {
  return writeGeoPackageLayer(
      path, layer_name, wkt, wkbPolygon,
      {{"id", OFTInteger}, {"class", OFTString}, {"height_m", OFTReal}, {"area_m2", OFTReal}},
      [&](OGRLayer* layer) {
        std::size_t written = 0;
        for (const LabelledPolygon& p : polygons) {
          if (p.ring.size() < 3) continue;
          auto ring = std::make_unique<OGRLinearRing>();
          for (const auto& v : p.ring) ring->addPoint(v[0], v[1]);
          ring->closeRings();
          OGRPolygon polygon;
          polygon.addRingDirectly(ring.release());
          OGRFeature feature(layer->GetLayerDefn());
          feature.SetField("id", p.id);
          feature.SetField("class", p.class_name.c_str());
          feature.SetField("height_m", p.height);
          feature.SetField("area_m2", polygon.get_Area());
          feature.SetGeometry(&polygon);
          if (layer->CreateFeature(&feature) != OGRERR_NONE) gdal::failed(path, "feature");
          ++written;
        }
        return written;
      });
}

#else

std::size_t writeLabelledPolygons(const std::string& path, const std::string&, const std::string&,
                                  const std::vector<LabelledPolygon>&) {
  throw Error(path, "GeoPackage", "a sadsplat build with GDAL (Debian: libgdal-dev)",
              "a build without it");
}

std::size_t writeObjectPolygons(const std::string& path, const std::vector<int>&, int, int,
                                const std::vector<MapObjectAttributes>&, const MapGrid&,
                                const std::vector<std::string>&, const ObjectPolygonOptions&) {
  throw Error(path, "GeoPackage", "a sadsplat build with GDAL (Debian: libgdal-dev)",
              "a build without it");
}

#endif

}  // namespace geo
}  // namespace sadsplat
