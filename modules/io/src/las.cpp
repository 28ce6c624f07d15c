// LAS 1.4 R15, point data record format 7. Offsets below are the specification's (table 3:
// public header block, table 4: VLR header, table 14: format 6, table 15: format 7).
#include "sadsplat/io/las.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "json_field.h"

namespace sadsplat {
namespace io {
namespace {

constexpr std::size_t kLasHeaderSize = 375;  // LAS 1.4 public header block
constexpr std::size_t kLasVlrHeaderSize = 54;
constexpr std::size_t kFormat6Length = 30;
constexpr std::size_t kFormat7Length = 36;
constexpr std::uint16_t kWktRecordId = 2112;
constexpr std::uint16_t kGlobalEncodingWkt = 1u << 4;

template <typename T>
void put(std::string& b, std::size_t at, T value) {
  static_assert(std::is_trivially_copyable<T>::value, "");
  unsigned char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));  // x86-64 and aarch64 are little endian, as LAS is
  std::memcpy(&b[at], bytes, sizeof(T));
}

template <typename T>
T get(const std::string& b, std::size_t at) {
  T value;
  std::memcpy(&value, &b[at], sizeof(T));
  return value;
}

void putText(std::string& b, std::size_t at, const std::string& text, std::size_t width) {
  std::memcpy(&b[at], text.data(), std::min(text.size(), width));  // the rest stays zero
}

std::int32_t scaled(double v, double scale, double offset, const std::string& path) {
  const double s = std::round((v - offset) / scale);
  if (!(std::abs(s) < 2147483647.0)) {
    throw Error(path, "X/Y/Z", "coordinates within 2^31 scale units of the offset",
                std::to_string(v));
  }
  return static_cast<std::int32_t>(s);
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

void writeLas(const std::string& path, const std::vector<LasPoint>& points, LasHeader h) {
  if (h.wkt.size() > 65000) {
    throw Error(path, "WKT", "a CRS description under 65,000 characters",
                std::to_string(h.wkt.size()));
  }
  for (int k = 0; k < 3; ++k) {
    if (!(h.scale[k] > 0)) throw Error(path, "scale", "positive scale factors", "0 or less");
  }
  std::array<double, 3> lo{0, 0, 0}, hi{0, 0, 0};
  if (!points.empty()) {
    lo = {points[0].x, points[0].y, points[0].z};
    hi = lo;
  }
  for (const LasPoint& p : points) {
    const double v[3] = {p.x, p.y, p.z};
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(v[k])) {
        throw Error(path, "X/Y/Z", "finite coordinates", std::to_string(v[k]));
      }
      lo[k] = std::min(lo[k], v[k]);
      hi[k] = std::max(hi[k], v[k]);
    }
  }
  for (int k = 0; k < 3; ++k) h.offset[k] = std::floor(lo[k]);
  h.min = lo;
  h.max = hi;
  h.point_count = points.size();

  const std::string wkt = h.wkt.empty() ? std::string() : h.wkt + '\0';
  const std::size_t vlr_bytes = wkt.empty() ? 0 : kLasVlrHeaderSize + wkt.size();
  std::string b(kLasHeaderSize + vlr_bytes, '\0');
  std::memcpy(&b[0], "LASF", 4);
  put<std::uint16_t>(b, 4, 0);                                     // file source id
  put<std::uint16_t>(b, 6, wkt.empty() ? 0 : kGlobalEncodingWkt);  // global encoding
  b[24] = 1;                                                       // version major
  b[25] = 4;                                                       // version minor
  putText(b, 26, h.system_identifier, 32);
  putText(b, 58, h.generating_software, 32);
  put<std::uint16_t>(b, 90, 1);     // creation day of year (the content, not the clock,
  put<std::uint16_t>(b, 92, 2026);  // decides the bytes: files are reproducible)
  put<std::uint16_t>(b, 94, static_cast<std::uint16_t>(kLasHeaderSize));
  put<std::uint32_t>(b, 96, static_cast<std::uint32_t>(kLasHeaderSize + vlr_bytes));
  put<std::uint32_t>(b, 100, wkt.empty() ? 0 : 1);  // number of VLRs
  b[104] = 7;                                       // point data record format
  put<std::uint16_t>(b, 105, static_cast<std::uint16_t>(kFormat7Length));
  // 107: legacy point count and 111: legacy counts by return stay 0 (format 6+ must).
  for (int k = 0; k < 3; ++k) {
    put<double>(b, 131 + 8 * k, h.scale[k]);
    put<double>(b, 155 + 8 * k, h.offset[k]);
    put<double>(b, 179 + 16 * k, hi[k]);  // max X, min X, max Y, min Y, max Z, min Z
    put<double>(b, 187 + 16 * k, lo[k]);
  }
  // 227: waveform start, 235: first EVLR, 243: EVLR count: all 0.
  put<std::uint64_t>(b, 247, points.size());
  put<std::uint64_t>(b, 255, points.size());  // every point is return 1 of 1
  if (!wkt.empty()) {
    const std::size_t v = kLasHeaderSize;
    putText(b, v + 2, "LASF_Projection", 16);
    put<std::uint16_t>(b, v + 18, kWktRecordId);
    put<std::uint16_t>(b, v + 20, static_cast<std::uint16_t>(wkt.size()));
    putText(b, v + 22, "OGC coordinate system WKT", 32);
    std::memcpy(&b[v + kLasVlrHeaderSize], wkt.data(), wkt.size());
  }
  std::string records(points.size() * kFormat7Length, '\0');
  for (std::size_t i = 0; i < points.size(); ++i) {
    const LasPoint& p = points[i];
    const std::size_t r = i * kFormat7Length;
    put<std::int32_t>(records, r + 0, scaled(p.x, h.scale[0], h.offset[0], path));
    put<std::int32_t>(records, r + 4, scaled(p.y, h.scale[1], h.offset[1], path));
    put<std::int32_t>(records, r + 8, scaled(p.z, h.scale[2], h.offset[2], path));
    records[r + 14] = 0x11;  // return number 1, number of returns 1
    records[r + 16] = static_cast<char>(p.classification);
    for (int k = 0; k < 3; ++k) put<std::uint16_t>(records, r + 30 + 2 * k, p.rgb[k]);
  }
  writeFileAtomically(path, [&](std::ostream& out) {
    out.write(b.data(), static_cast<std::streamsize>(b.size()));
    out.write(records.data(), static_cast<std::streamsize>(records.size()));
  });
}

LasHeader forEachLasPoint(const std::string& path,
                          const std::function<void(const LasPoint&)>& visit) {
  requireRegularFile(path);
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw Error(path, "file", "a readable LAS file", "cannot open");
  const auto file_size = static_cast<std::uint64_t>(std::max<std::streamoff>(in.tellg(), 0));
  in.seekg(0);
  const auto readAt = [&](std::uint64_t at, std::size_t n, const char* field) {
    std::string bytes(n, '\0');
    in.seekg(static_cast<std::streamoff>(at));
    if (!in.read(&bytes[0], static_cast<std::streamsize>(n))) {
      throw Error(path, field, std::to_string(n) + " bytes at offset " + std::to_string(at),
                  "a truncated file");
    }
    return bytes;
  };
  if (file_size < kLasHeaderSize) {
    throw Error(path, "signature", "a LAS file (\"LASF\" and a 375-byte header)",
                "a file of " + std::to_string(file_size) + " bytes");
  }
  const std::string b = readAt(0, kLasHeaderSize, "header");
  if (b.compare(0, 4, "LASF") != 0) {
    throw Error(path, "signature", "a LAS file (\"LASF\" and a 375-byte header)",
                "\"" + b.substr(0, 4) + "\"");
  }
  LasHeader h;
  h.version_minor = static_cast<unsigned char>(b[25]);
  if (b[24] != 1 || h.version_minor != 4) {
    throw Error(path, "version", "LAS 1.4",
                std::to_string(int(b[24])) + "." + std::to_string(h.version_minor));
  }
  const int format = static_cast<unsigned char>(b[104]);
  h.point_format = format;
  if (format & 0xC0) throw Error(path, "point data format", "uncompressed LAS", "LAZ");
  const std::size_t length = get<std::uint16_t>(b, 105);
  const std::size_t need = format == 7 ? kFormat7Length : format == 6 ? kFormat6Length : 0;
  if (need == 0) throw Error(path, "point data format", "6 or 7", std::to_string(format));
  if (length < need) {
    throw Error(path, "point data record length", "at least " + std::to_string(need),
                std::to_string(length));
  }
  const std::size_t header_size = get<std::uint16_t>(b, 94);
  const std::uint64_t data_offset = get<std::uint32_t>(b, 96);
  const std::uint32_t vlr_count = get<std::uint32_t>(b, 100);
  h.point_count = get<std::uint64_t>(b, 247);
  const char* kAxes[3] = {"X", "Y", "Z"};
  for (int k = 0; k < 3; ++k) {
    h.scale[k] = get<double>(b, 131 + 8 * k);
    h.offset[k] = get<double>(b, 155 + 8 * k);
    h.max[k] = get<double>(b, 179 + 16 * k);
    h.min[k] = get<double>(b, 187 + 16 * k);
    // Every stored integer times the scale plus the offset must be a finite coordinate.
    if (!(h.scale[k] > 0 && h.scale[k] <= 1e3)) {
      throw Error(path, std::string(kAxes[k]) + " scale factor", "a positive scale up to 1000",
                  std::to_string(h.scale[k]));
    }
    if (!(std::abs(h.offset[k]) <= 1e12)) {
      throw Error(path, std::string(kAxes[k]) + " offset", "a finite offset within +-1e12",
                  std::to_string(h.offset[k]));
    }
    if (!(std::isfinite(h.min[k]) && std::isfinite(h.max[k]) && h.min[k] <= h.max[k]) &&
        h.point_count > 0) {
      throw Error(path, std::string("min / max ") + kAxes[k], "finite bounds with min <= max",
                  std::to_string(h.min[k]) + " / " + std::to_string(h.max[k]));
    }
  }
  if (header_size < kLasHeaderSize || data_offset < header_size || data_offset > file_size) {
    throw Error(path, "offset to point data", "inside the file, after the header",
                std::to_string(data_offset));
  }
  const std::uint64_t available = (file_size - data_offset) / length;
  if (h.point_count > available) {
    throw Error(path, "number of point records",
                "at most " + std::to_string(available) + " (the file's size)",
                std::to_string(h.point_count));
  }
  std::uint64_t v = header_size;
  for (std::uint32_t i = 0; i < vlr_count; ++i) {
    if (v + kLasVlrHeaderSize > data_offset) {
      throw Error(path, "VLR " + std::to_string(i), "a record before the point data",
                  "one running past it");
    }
    const std::string vh = readAt(v, kLasVlrHeaderSize, "VLR header");
    const std::size_t len = get<std::uint16_t>(vh, 20);
    if (v + kLasVlrHeaderSize + len > data_offset) {
      throw Error(path, "VLR " + std::to_string(i), "a record before the point data",
                  "one running past it");
    }
    const std::string user(vh.data() + 2, strnlen(vh.data() + 2, 16));
    if (user == "LASF_Projection" && get<std::uint16_t>(vh, 18) == kWktRecordId) {
      const std::string body = readAt(v + kLasVlrHeaderSize, len, "WKT record");
      h.wkt.assign(body.data(), strnlen(body.data(), len));
    }
    v += kLasVlrHeaderSize + len;
  }
  // The points, streamed in blocks: memory stays bounded whatever the file's size.
  std::array<double, 3> lo{std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::infinity()};
  std::array<double, 3> hi{-lo[0], -lo[1], -lo[2]};
  constexpr std::uint64_t kBlock = 65536;
  std::string block;
  LasPoint p;
  for (std::uint64_t first = 0; first < h.point_count; first += kBlock) {
    const std::uint64_t n = std::min(kBlock, h.point_count - first);
    block = readAt(data_offset + first * length, static_cast<std::size_t>(n * length),
                   "point records");
    for (std::uint64_t i = 0; i < n; ++i) {
      const std::size_t r = static_cast<std::size_t>(i * length);
      p.x = get<std::int32_t>(block, r + 0) * h.scale[0] + h.offset[0];
      p.y = get<std::int32_t>(block, r + 4) * h.scale[1] + h.offset[1];
      p.z = get<std::int32_t>(block, r + 8) * h.scale[2] + h.offset[2];
      p.classification = static_cast<std::uint8_t>(block[r + 16]);
      if (format == 7) {
        for (int k = 0; k < 3; ++k) p.rgb[k] = get<std::uint16_t>(block, r + 30 + 2 * k);
      }
      const double xyz[3] = {p.x, p.y, p.z};
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], xyz[k]);
        hi[k] = std::max(hi[k], xyz[k]);
      }
      visit(p);
    }
  }
  // The header's bounds must hold the points (within a scale unit: writers round); a header
  // whose bounds disagree with its points is refused rather than summarised.
  for (int k = 0; k < 3 && h.point_count > 0; ++k) {
    const double slack = h.scale[k] + 1e-9 * std::max(std::abs(lo[k]), std::abs(hi[k]));
    if (lo[k] < h.min[k] - slack || hi[k] > h.max[k] + slack) {
      std::ostringstream got;
      got << "header " << h.min[k] << " .. " << h.max[k] << ", points " << lo[k] << " .. " << hi[k];
      throw Error(path, std::string("min / max ") + kAxes[k], "bounds that hold the points",
                  got.str());
    }
  }
  return h;
}

std::vector<LasPoint> readLas(const std::string& path, LasHeader* out_header) {
  std::vector<LasPoint> points;
  const LasHeader h = forEachLasPoint(path, [&](const LasPoint& p) { points.push_back(p); });
  if (out_header) *out_header = h;
  return points;
}

const std::map<int, std::string>& asprsClassNames() {
  static const std::map<int, std::string> names = {{0, "created, never classified"},
                                                   {1, "unclassified"},
                                                   {2, "ground"},
                                                   {3, "low vegetation"},
                                                   {4, "medium vegetation"},
                                                   {5, "high vegetation"},
                                                   {6, "building"},
                                                   {7, "low point (noise)"},
                                                   {9, "water"},
                                                   {10, "rail"},
                                                   {11, "road surface"},
                                                   {17, "bridge deck"},
                                                   {18, "high noise"}};
  return names;
}

int defaultAsprsCode(const std::string& class_name, int class_id) {
  const std::string n = lower(class_name);
  auto has = [&](std::initializer_list<const char*> words) {
    for (const char* w : words) {
      if (n.find(w) != std::string::npos) return true;
    }
    return false;
  };
  // Order matters: "low vegetation" before "vegetation", "railway" before "way".
  if (has({"bridge"})) return 17;
  if (has({"rail"})) return 10;
  if (has({"water", "river", "sea", "lake", "pond", "canal"})) return 9;
  if (has({"building", "roof", "house"})) return 6;
  if (has({"low veg", "grass", "lawn", "field", "crop", "meadow"})) return 3;
  if (has({"shrub", "bush"})) return 4;
  if (has({"tree", "forest", "vegetation"})) return 5;
  if (has({"road", "street", "asphalt", "pavement", "parking", "path", "highway"})) return 11;
  if (has({"ground", "soil", "bare", "sand", "earth", "dirt", "terrain"})) return 2;
  return std::min(255, 64 + class_id);
}

std::vector<int> asprsCodes(const std::vector<std::string>& class_names,
                            const std::string& mapping_json_path) {
  std::vector<int> codes(class_names.size());
  for (std::size_t i = 0; i < class_names.size(); ++i) {
    codes[i] = defaultAsprsCode(class_names[i], static_cast<int>(i));
  }
  if (mapping_json_path.empty()) return codes;
  const nlohmann::json parsed = readJsonFile(mapping_json_path);
  const JsonField j(parsed, mapping_json_path);
  if (!j.isObject()) j.fail("an object {\"class name\": ASPRS code}");
  for (auto it = parsed.begin(); it != parsed.end(); ++it) {
    const auto found = std::find(class_names.begin(), class_names.end(), it.key());
    if (found == class_names.end()) {
      std::string list;
      for (const auto& n : class_names) list += (list.empty() ? "" : ", ") + n;
      throw Error(mapping_json_path, it.key(), "a class of the model (" + list + ")",
                  "an unknown name");
    }
    codes[found - class_names.begin()] =
        static_cast<int>(JsonField(it.value(), mapping_json_path, it.key()).integer(0, 255));
  }
  return codes;
}

}  // namespace io
}  // namespace sadsplat
