#include "sadsplat/io/georeference.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "json_field.h"
#include "sadsplat/common/error.h"
#include "sadsplat/io/filesystem.h"

#if SADSPLAT_HAVE_EXIF
#include <libexif/exif-data.h>
#endif

namespace sadsplat {
namespace io {
namespace {

#if SADSPLAT_HAVE_EXIF
// Degrees from an EXIF triple of rationals (degrees, minutes, seconds).
double exifDegrees(const std::string& path, ExifEntry* e, ExifByteOrder order, const char* tag) {
  if (e->format != EXIF_FORMAT_RATIONAL || e->components < 1) {
    throw Error(path, std::string("EXIF ") + tag, "rationals (degrees, minutes, seconds)",
                "format " + std::to_string(e->format));
  }
  double value = 0, unit = 1;
  const unsigned size = exif_format_get_size(e->format);
  for (unsigned k = 0; k < std::min<unsigned>(3, e->components); ++k) {
    const ExifRational r = exif_get_rational(e->data + k * size, order);
    if (r.denominator == 0) {
      throw Error(path, std::string("EXIF ") + tag, "rationals with a non-zero denominator",
                  std::to_string(r.numerator) + "/0");
    }
    value += unit * r.numerator / r.denominator;
    unit /= 60;
  }
  return value;
}
#endif

}  // namespace

bool haveExif() { return SADSPLAT_HAVE_EXIF != 0; }

std::optional<GeoPosition> readExifGps(const std::string& path) {
#if SADSPLAT_HAVE_EXIF
  requireRegularFile(path);
  ExifData* data = exif_data_new_from_file(path.c_str());
  if (data == nullptr) return std::nullopt;
  struct Release {
    ExifData* d;
    ~Release() { exif_data_unref(d); }
  } release{data};
  const ExifByteOrder order = exif_data_get_byte_order(data);
  ExifContent* gps = data->ifd[EXIF_IFD_GPS];
  const auto entry = [&](int tag) {
    return gps ? exif_content_get_entry(gps, static_cast<ExifTag>(tag)) : nullptr;
  };
  ExifEntry* lat = entry(0x0002);
  ExifEntry* lon = entry(0x0004);
  if (lat == nullptr || lon == nullptr) return std::nullopt;
  GeoPosition p;
  p.latitude = exifDegrees(path, lat, order, "GPSLatitude");
  p.longitude = exifDegrees(path, lon, order, "GPSLongitude");
  ExifEntry* lat_ref = entry(0x0001);
  ExifEntry* lon_ref = entry(0x0003);
  if (lat_ref && lat_ref->size > 0 && lat_ref->data[0] == 'S') p.latitude = -p.latitude;
  if (lon_ref && lon_ref->size > 0 && lon_ref->data[0] == 'W') p.longitude = -p.longitude;
  if (ExifEntry* alt = entry(0x0006)) {
    if (alt->format == EXIF_FORMAT_RATIONAL && alt->components >= 1) {
      const ExifRational r = exif_get_rational(alt->data, order);
      if (r.denominator != 0) p.altitude = static_cast<double>(r.numerator) / r.denominator;
    }
    ExifEntry* alt_ref = entry(0x0005);
    if (alt_ref && alt_ref->size > 0 && alt_ref->data[0] == 1) p.altitude = -p.altitude;
  }
  // The receiver's own accuracy: GPSHPositioningError (metres), else GPSDOP.
  const auto positive_rational = [&](int tag) -> double {
    ExifEntry* e = entry(tag);
    if (e == nullptr || e->format != EXIF_FORMAT_RATIONAL || e->components < 1) return 0;
    const ExifRational r = exif_get_rational(e->data, order);
    const double v = r.denominator != 0 ? static_cast<double>(r.numerator) / r.denominator : 0;
    return std::isfinite(v) && v > 0 ? v : 0;
  };
  if (const double error = positive_rational(0x001F); error > 0) {
    p.horizontal_accuracy = error;
  } else if (const double dop = positive_rational(0x000B); dop > 0) {
    p.horizontal_accuracy = 3.0 * dop;
  }
  if (!(std::abs(p.latitude) <= 90) || !(std::abs(p.longitude) <= 180)) {
    throw Error(path, "EXIF GPS position", "latitude within +-90, longitude within +-180 degrees",
                std::to_string(p.latitude) + ", " + std::to_string(p.longitude));
  }
  return p;
#else
  (void)path;
  return std::nullopt;
#endif
}

std::vector<unsigned char> jpegWithExifGps(const std::vector<unsigned char>& jpeg,
                                           const GeoPosition& gps, int focal_length_35mm) {
  if (jpeg.size() < 2 || jpeg[0] != 0xFF || jpeg[1] != 0xD8) {
    throw Error("<jpeg>", "start", "a JPEG SOI marker (FF D8)", "other bytes");
  }
  // TIFF, little endian: header, IFD0 (the Exif IFD pointer when there is a focal length, the
  // GPS IFD pointer; tags ascending), the Exif IFD (1 entry), the GPS IFD (7 entries), values.
  std::vector<unsigned char> t;
  const auto u16 = [&](std::uint32_t v) {
    t.push_back(v & 0xFF);
    t.push_back((v >> 8) & 0xFF);
  };
  const auto u32 = [&](std::uint32_t v) {
    for (int k = 0; k < 4; ++k) t.push_back((v >> (8 * k)) & 0xFF);
  };
  const bool focal = focal_length_35mm > 0;
  const std::uint32_t ifd0 = 8, ifd0_entries = focal ? 2 : 1, entries = 7;
  const std::uint32_t exif_ifd = ifd0 + 2 + 12 * ifd0_entries + 4;
  const std::uint32_t gps_ifd = focal ? exif_ifd + 2 + 12 + 4 : exif_ifd;
  const std::uint32_t values = gps_ifd + 2 + 12 * entries + 4;
  t.insert(t.end(), {'I', 'I', 42, 0});
  u32(ifd0);
  u16(ifd0_entries);
  if (focal) {
    u16(0x8769), u16(4), u32(1), u32(exif_ifd);  // ExifIFDPointer
  }
  u16(0x8825), u16(4), u32(1), u32(gps_ifd);  // GPSInfo
  u32(0);
  if (focal) {
    u16(1);
    // FocalLengthIn35mmFilm, SHORT
    u16(0xA405), u16(3), u32(1), u16(static_cast<std::uint32_t>(focal_length_35mm)), u16(0);
    u32(0);
  }
  const auto dms = [](double deg, std::uint32_t out[6]) {
    deg = std::abs(deg);
    const double d = std::floor(deg), m = std::floor((deg - d) * 60);
    const double s = ((deg - d) * 60 - m) * 60;
    out[0] = static_cast<std::uint32_t>(d), out[1] = 1;
    out[2] = static_cast<std::uint32_t>(m), out[3] = 1;
    out[4] = static_cast<std::uint32_t>(std::llround(s * 1e6)), out[5] = 1000000;
  };
  std::uint32_t lat[6], lon[6];
  dms(gps.latitude, lat);
  dms(gps.longitude, lon);
  const std::uint32_t alt[2] = {
      static_cast<std::uint32_t>(std::llround(std::abs(gps.altitude) * 1000)), 1000};
  u16(entries);
  const auto ascii = [&](std::uint16_t tag, char c) {
    u16(tag), u16(2), u32(2);
    t.push_back(c), t.push_back(0), t.push_back(0), t.push_back(0);
  };
  u16(0x0000), u16(1), u32(4), t.insert(t.end(), {2, 3, 0, 0});  // GPSVersionID 2.3.0.0
  ascii(0x0001, gps.latitude < 0 ? 'S' : 'N');
  u16(0x0002), u16(5), u32(3), u32(values);
  ascii(0x0003, gps.longitude < 0 ? 'W' : 'E');
  u16(0x0004), u16(5), u32(3), u32(values + 24);
  u16(0x0005), u16(1), u32(1),
      t.insert(t.end(), {static_cast<unsigned char>(gps.altitude < 0), 0, 0, 0});
  u16(0x0006), u16(5), u32(1), u32(values + 48);
  u32(0);
  for (auto v : lat) u32(v);
  for (auto v : lon) u32(v);
  for (auto v : alt) u32(v);
  std::vector<unsigned char> app1 = {0xFF, 0xE1, 0, 0, 'E', 'x', 'i', 'f', 0, 0};
  app1.insert(app1.end(), t.begin(), t.end());
  const std::size_t length = app1.size() - 2;
  app1[2] = static_cast<unsigned char>(length >> 8);
  app1[3] = static_cast<unsigned char>(length & 0xFF);
  std::vector<unsigned char> out(jpeg.begin(), jpeg.begin() + 2);
  out.insert(out.end(), app1.begin(), app1.end());
  out.insert(out.end(), jpeg.begin() + 2, jpeg.end());
  return out;
}

int utmEpsg(const GeoPosition& p) {
  const int zone = std::clamp(static_cast<int>(std::floor((p.longitude + 180) / 6)) + 1, 1, 60);
  return (p.latitude >= 0 ? 32600 : 32700) + zone;
}

std::array<double, 3> Similarity::apply(const std::array<double, 3>& x) const {
  std::array<double, 3> y{};
  for (int r = 0; r < 3; ++r) {
    y[r] = translation[r] + scale * (rotation[3 * r] * x[0] + rotation[3 * r + 1] * x[1] +
                                     rotation[3 * r + 2] * x[2]);
  }
  return y;
}

std::string georeferenceToJson(const Georeference& g) {
  const nlohmann::json j = {{"frame", "east-north-up metres around origin (WGS84)"},
                            {"origin",
                             {{"latitude", g.origin.latitude},
                              {"longitude", g.origin.longitude},
                              {"altitude", g.origin.altitude}}},
                            {"epsg_utm", g.epsg_utm},
                            {"sfm_to_local",
                             {{"scale", g.sfm_to_local.scale},
                              {"rotation", g.sfm_to_local.rotation},
                              {"translation", g.sfm_to_local.translation}}},
                            {"photos_with_gps", g.photos_with_gps},
                            {"inliers", g.inliers},
                            {"consensus", g.consensus},
                            {"rms_metres", g.rms_metres}};
  nlohmann::json out = j;
  if (!g.up_source.empty()) {
    out["up_source"] = g.up_source;
    out["gps_accuracy_metres"] = g.gps_accuracy_metres;
    out["gps_noise_metres"] = g.gps_noise_metres;
    out["inlier_metres"] = g.inlier_metres;
    out["horizontal_rms_metres"] = g.horizontal_rms_metres;
    out["vertical_rms_metres"] = g.vertical_rms_metres;
    out["scale_uncertainty"] = g.scale_uncertainty;
    out["ground_tilt_deg"] = g.ground_tilt_deg;
    out["views_tilt_deg"] = g.views_tilt_deg;
    out["doubts"] = g.doubts;
    out["control_points"] = g.control_points;
    out["check_points"] = g.check_points;
    out["check_rmse_horizontal"] = g.check_rmse_horizontal;
    out["check_rmse_vertical"] = g.check_rmse_vertical;
  }
  return out.dump(2) + "\n";
}

Georeference georeferenceFromJson(const std::string& text, const std::string& origin) {
  Georeference g;
  const nlohmann::json parsed = parseJson(text, origin);
  const JsonField j(parsed, origin);
  const JsonField o = j["origin"];
  g.origin = {o["latitude"].number(-90, 90), o["longitude"].number(-180, 180),
              o["altitude"].number(-100000, 100000)};
  const JsonField epsg = j["epsg_utm"];
  // The UTM zone of the origin (sadsplat writes that one) or a neighbouring zone of the same
  // hemisphere: another code would put the maps on a distorted or a wrong grid.
  const int own = utmEpsg(g.origin);
  const double code = epsg.number();
  if (!(std::abs(code - own) <= 1) || std::floor(code) != code ||
      static_cast<int>(code) / 100 != own / 100) {
    epsg.fail("the WGS84 / UTM zone of the origin, EPSG:" + std::to_string(own) +
              " (or a neighbouring zone)");
  }
  g.epsg_utm = static_cast<int>(code);
  if (j.has("sfm_to_local")) {
    const JsonField s = j["sfm_to_local"];
    g.sfm_to_local.scale = s["scale"].number(1e-12, 1e12);
    const JsonField r = s["rotation"], t = s["translation"];
    if (r.size() != 9) r.fail("9 numbers (a row-major rotation)");
    if (t.size() != 3) t.fail("3 numbers");
    for (std::size_t k = 0; k < 9; ++k) g.sfm_to_local.rotation[k] = r.at(k).number(-1.001, 1.001);
    for (std::size_t k = 0; k < 3; ++k) g.sfm_to_local.translation[k] = t.at(k).number();
  }
  const auto count = [&](const char* key) {
    return j.has(key) ? static_cast<int>(j[key].integer(0, 1 << 30)) : 0;
  };
  g.photos_with_gps = count("photos_with_gps");
  g.inliers = count("inliers");
  g.rms_metres = j.has("rms_metres") ? j["rms_metres"].number() : 0.0;
  g.consensus = j.has("consensus") ? j["consensus"].boolean() : true;  // older files: none
  if (j.has("up_source")) {
    g.up_source = j["up_source"].text();
    const auto optional = [&](const char* key, double fallback) {
      return j.has(key) ? j[key].number() : fallback;
    };
    g.gps_accuracy_metres = optional("gps_accuracy_metres", 0);
    g.gps_noise_metres = optional("gps_noise_metres", 0);
    g.inlier_metres = optional("inlier_metres", 0);
    g.horizontal_rms_metres = optional("horizontal_rms_metres", 0);
    g.vertical_rms_metres = optional("vertical_rms_metres", 0);
    g.scale_uncertainty = optional("scale_uncertainty", 0);
    g.ground_tilt_deg = optional("ground_tilt_deg", -1);
    g.views_tilt_deg = optional("views_tilt_deg", -1);
    g.control_points = count("control_points");
    g.check_points = count("check_points");
    g.check_rmse_horizontal = optional("check_rmse_horizontal", -1);
    g.check_rmse_vertical = optional("check_rmse_vertical", -1);
    if (j.has("doubts")) {
      for (const JsonField& d : j["doubts"].elements()) g.doubts.push_back(d.text());
    }
  }
  return g;
}

}  // namespace io
}  // namespace sadsplat
