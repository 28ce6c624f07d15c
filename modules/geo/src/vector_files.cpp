#include "sadsplat/geo/vector_files.h"

#include <algorithm>
#include <memory>
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

}  // namespace

std::size_t writeClassPolygons(const std::string& path, const Raster& classes, const MapGrid& grid,
                               const std::vector<std::string>& names,
                               const ClassPolygonOptions& o) {
  if (classes.bands != 1 || classes.type != Raster::Type::kByte) {
    throw Error(path, "class map", "a 1-band 8-bit raster of class ids", "another raster");
  }
  classes.check(path);
  gdal::init();
  // The class ids and a mask of the selected classes, in memory.
  GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
  gdal::Dataset raster(mem->Create("", classes.width, classes.height, 2, GDT_Byte, nullptr));
  if (!raster) gdal::failed(path, "polygonize");
  double transform[6] = {grid.x0, grid.gsd, 0, grid.y0, 0, -grid.gsd};
  raster->SetGeoTransform(transform);
  std::vector<std::uint8_t> mask(classes.bytes.size(), 0);
  for (std::size_t i = 0; i < mask.size(); ++i) {
    mask[i] =
        std::find(o.classes.begin(), o.classes.end(), int(classes.bytes[i])) != o.classes.end();
  }
  GDALRasterBand* ids = raster->GetRasterBand(1);
  GDALRasterBand* selected = raster->GetRasterBand(2);
  if (ids->RasterIO(GF_Write, 0, 0, classes.width, classes.height,
                    const_cast<std::uint8_t*>(classes.bytes.data()), classes.width, classes.height,
                    GDT_Byte, 0, 0, nullptr) != CE_None ||
      selected->RasterIO(GF_Write, 0, 0, classes.width, classes.height, mask.data(), classes.width,
                         classes.height, GDT_Byte, 0, 0, nullptr) != CE_None) {
    gdal::failed(path, "polygonize");
  }
  // Polygonized into a memory layer first: then filtered, simplified and written.
  GDALDriver* memory = GetGDALDriverManager()->GetDriverByName("Memory");
  gdal::Dataset scratch(memory->Create("", 0, 0, 0, GDT_Unknown, nullptr));
  if (!scratch) gdal::failed(path, "polygonize");
  OGRLayer* raw = scratch->CreateLayer("raw", nullptr, wkbPolygon, nullptr);
  OGRFieldDefn id_field("class_id", OFTInteger);
  if (!raw || raw->CreateField(&id_field) != OGRERR_NONE) gdal::failed(path, "polygonize");
  char eight[] = "8CONNECTED=8";
  char* options[] = {eight, nullptr};
  if (GDALPolygonize(ids, selected, raw, 0, options, nullptr, nullptr) != CE_None) {
    gdal::failed(path, "polygonize");
  }
  return writeGeoPackageLayer(
      path, o.layer, grid.wkt, wkbMultiPolygon,
      {{"class_id", OFTInteger}, {"class", OFTString}, {"area_m2", OFTReal}}, [&](OGRLayer* layer) {
        std::size_t written = 0;
        raw->ResetReading();
        for (std::unique_ptr<OGRFeature> f(raw->GetNextFeature()); f;
             f.reset(raw->GetNextFeature())) {
          const OGRGeometry* g = f->GetGeometryRef();
          if (!g) continue;
          std::unique_ptr<OGRGeometry> shape(
              o.simplify > 0 ? g->SimplifyPreserveTopology(o.simplify) : g->clone());
          if (!shape || shape->IsEmpty()) continue;
          const double a = OGR_G_Area(OGRGeometry::ToHandle(shape.get()));
          if (a < o.min_area) continue;
          const int id = f->GetFieldAsInteger(0);
          OGRFeature feature(layer->GetLayerDefn());
          feature.SetField("class_id", id);
          feature.SetField("class", id >= 0 && id < static_cast<int>(names.size())
                                        ? names[static_cast<std::size_t>(id)].c_str()
                                        : "");
          feature.SetField("area_m2", a);
          feature.SetGeometryDirectly(OGRGeometryFactory::forceToMultiPolygon(shape.release()));
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

std::size_t writeClassPolygons(const std::string& path, const Raster&, const MapGrid&,
                               const std::vector<std::string>&, const ClassPolygonOptions&) {
  throw Error(path, "GeoPackage", "a sadsplat build with GDAL (Debian: libgdal-dev)",
              "a build without it");
}

#endif

}  // namespace geo
}  // namespace sadsplat
