#include "sadsplat/geo/raster_files.h"

#include <memory>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"

#if SADSPLAT_HAVE_GDAL
#include <cpl_conv.h>
#include <cpl_string.h>
#include <gdal_priv.h>
#include <ogr_spatialref.h>

#include "gdal_support.h"
#endif

namespace sadsplat {
namespace geo {

Raster Raster::bytesOf(int width, int height, int bands) {
  Raster r;
  r.width = width;
  r.height = height;
  r.bands = bands;
  r.type = Type::kByte;
  r.bytes.assign(static_cast<std::size_t>(width) * height * bands, 0);
  return r;
}

Raster Raster::floatsOf(int width, int height) {
  Raster r;
  r.width = width;
  r.height = height;
  r.type = Type::kFloat32;
  r.floats.assign(static_cast<std::size_t>(width) * height, 0.f);
  return r;
}

void Raster::check(const std::string& path) const {
  const std::size_t n = static_cast<std::size_t>(width) * height * bands;
  const std::size_t have = type == Type::kByte     ? bytes.size()
                           : type == Type::kUInt16 ? words.size()
                                                   : floats.size();
  if (width <= 0 || height <= 0 || bands <= 0 || have != n) {
    throw Error(path, "raster",
                std::to_string(n) + " samples (" + std::to_string(width) + "x" +
                    std::to_string(height) + "x" + std::to_string(bands) + ")",
                std::to_string(have));
  }
}

#if SADSPLAT_HAVE_GDAL
namespace {

using gdal::Dataset;

void initGdal() { gdal::init(); }

GDALDataType gdalType(Raster::Type t) {
  return t == Raster::Type::kByte     ? GDT_Byte
         : t == Raster::Type::kUInt16 ? GDT_UInt16
                                      : GDT_Float32;
}

int sampleSize(Raster::Type t) {
  return t == Raster::Type::kByte ? 1 : t == Raster::Type::kUInt16 ? 2 : 4;
}

void* samples(const Raster& r) {
  return r.type == Raster::Type::kByte     ? (void*)r.bytes.data()
         : r.type == Raster::Type::kUInt16 ? (void*)r.words.data()
                                           : (void*)r.floats.data();
}

[[noreturn]] void gdalFailed(const std::string& path, const char* what) {
  gdal::failed(path, what);
}

void fill(GDALDataset* ds, const Raster& r, const std::string& path) {
  const int size = sampleSize(r.type);
  if (ds->RasterIO(GF_Write, 0, 0, r.width, r.height, samples(r), r.width, r.height,
                   gdalType(r.type), r.bands, nullptr, static_cast<GSpacing>(size) * r.bands,
                   static_cast<GSpacing>(size) * r.bands * r.width, size, nullptr) != CE_None) {
    gdalFailed(path, "pixels");
  }
  for (int b = 1; b <= r.bands; ++b) {
    GDALRasterBand* band = ds->GetRasterBand(b);
    const bool alpha = r.last_band_is_alpha && b == r.bands;
    if (alpha) band->SetColorInterpretation(GCI_AlphaBand);
    if (r.nodata && !alpha) band->SetNoDataValue(*r.nodata);
  }
  if (!r.palette.empty() && r.bands == 1 && r.type == Raster::Type::kByte) {
    GDALColorTable table;
    for (std::size_t i = 0; i < 256; ++i) {
      GDALColorEntry e{0, 0, 0, 0};  // unused entries (and nodata) transparent
      if (i < r.palette.size()) e = {r.palette[i][0], r.palette[i][1], r.palette[i][2], 255};
      table.SetColorEntry(static_cast<int>(i), &e);
    }
    ds->GetRasterBand(1)->SetColorTable(&table);
  }
}

}  // namespace

void writeGeoTiff(const std::string& path, const Raster& r, const MapGrid* grid) {
  r.check(path);
  initGdal();
  io::writeViaTemporaryPath(path, [&](const std::string& tmp) {
    GDALDriver* driver = GetGDALDriverManager()->GetDriverByName("GTiff");
    CPLStringList options;
    options.SetNameValue("COMPRESS", "DEFLATE");
    options.SetNameValue("TILED", "YES");
    if (r.type == Raster::Type::kFloat32) options.SetNameValue("PREDICTOR", "3");
    if (r.last_band_is_alpha) options.SetNameValue("ALPHA", "YES");
    if (r.bands >= 3 && r.type == Raster::Type::kByte) options.SetNameValue("PHOTOMETRIC", "RGB");
    Dataset ds(
        driver->Create(tmp.c_str(), r.width, r.height, r.bands, gdalType(r.type), options.List()));
    if (!ds) gdalFailed(path, "create");
    if (grid) {
      double transform[6] = {grid->x0, grid->gsd, 0, grid->y0, 0, -grid->gsd};
      ds->SetGeoTransform(transform);
      if (!grid->wkt.empty() && ds->SetProjection(grid->wkt.c_str()) != CE_None) {
        gdalFailed(path, "CRS");
      }
    }
    fill(ds.get(), r, path);
    CPLErrorReset();
    GDALClose(ds.release());
    if (CPLGetLastErrorType() >= CE_Failure) gdalFailed(path, "close");
  });
}

void writePng(const std::string& path, const Raster& r) {
  r.check(path);
  if (r.type == Raster::Type::kFloat32) {
    throw Error(path, "raster", "8- or 16-bit samples for a PNG", "float32");
  }
  initGdal();
  io::writeViaTemporaryPath(path, [&](const std::string& tmp) {
    GDALDriver* mem = GetGDALDriverManager()->GetDriverByName("MEM");
    Dataset ds(mem->Create("", r.width, r.height, r.bands, gdalType(r.type), nullptr));
    if (!ds) gdalFailed(path, "create");
    fill(ds.get(), r, path);
    GDALDriver* png = GetGDALDriverManager()->GetDriverByName("PNG");
    Dataset out(png->CreateCopy(tmp.c_str(), ds.get(), FALSE, nullptr, nullptr, nullptr));
    if (!out) gdalFailed(path, "create");
    CPLErrorReset();
    GDALClose(out.release());
    if (CPLGetLastErrorType() >= CE_Failure) gdalFailed(path, "close");
  });
}

Raster readByteRaster(const std::string& path) {
  initGdal();
  Dataset ds(static_cast<GDALDataset*>(GDALOpen(path.c_str(), GA_ReadOnly)));
  if (!ds) {
    throw Error(path, "raster", "an image GDAL can read",
                CPLGetLastErrorMsg()[0] ? CPLGetLastErrorMsg() : "cannot open");
  }
  GDALRasterBand* band = ds->GetRasterBand(1);
  if (!band || band->GetRasterDataType() != GDT_Byte) {
    throw Error(path, "band 1", "8-bit samples",
                band ? GDALGetDataTypeName(band->GetRasterDataType()) : "no band");
  }
  Raster r = Raster::bytesOf(ds->GetRasterXSize(), ds->GetRasterYSize(), 1);
  if (band->RasterIO(GF_Read, 0, 0, r.width, r.height, r.bytes.data(), r.width, r.height, GDT_Byte,
                     0, 0) != CE_None) {
    throw Error(path, "pixels", "a readable image", CPLGetLastErrorMsg());
  }
  return r;
}

std::optional<std::array<int, 2>> imageFileSize(const std::string& path) {
  initGdal();
  CPLPushErrorHandler(CPLQuietErrorHandler);
  Dataset ds(static_cast<GDALDataset*>(GDALOpen(path.c_str(), GA_ReadOnly)));
  CPLPopErrorHandler();
  if (!ds) return std::nullopt;
  return std::array<int, 2>{ds->GetRasterXSize(), ds->GetRasterYSize()};
}

#else

Raster readByteRaster(const std::string& path) {
  throw Error(path, "raster", "a sadsplat build with GDAL (Debian: libgdal-dev)",
              "a build without it");
}

std::optional<std::array<int, 2>> imageFileSize(const std::string&) { return std::nullopt; }

void writeGeoTiff(const std::string& path, const Raster&, const MapGrid*) {
  throw Error(path, "GeoTIFF", "a sadsplat build with GDAL (Debian: libgdal-dev)",
              "a build without it");
}

void writePng(const std::string& path, const Raster&) {
  throw Error(path, "PNG", "a sadsplat build with GDAL (Debian: libgdal-dev)",
              "a build without it");
}

#endif

}  // namespace geo
}  // namespace sadsplat
