#include "pcd_codec.h"

#include <cmath>
#include <cstring>
#include <set>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"

namespace sadsplat {
namespace io {
namespace pcd {
namespace {

// Upper bounds that keep every size computation far from overflow; real files are far below.
constexpr std::size_t kMaxPoints = std::size_t{1} << 36;
constexpr std::size_t kMaxCount = 1 << 16;
constexpr std::size_t kMaxFields = 1 << 12;
// LZF turns at most 3 input bytes into 264 output bytes (a long back-reference).
constexpr std::size_t kMaxLzfRatio = 100;
// More than any real header (a field name per FIELDS entry, at most 4096 of them).
constexpr std::size_t kMaxHeaderBytes = std::size_t{1} << 24;

bool parseUnsigned(const std::string& text, std::size_t limit, std::size_t* value) {
  if (text.empty() || text.size() > 12) return false;
  std::size_t v = 0;
  for (const char c : text) {
    if (c < '0' || c > '9') return false;
    v = v * 10 + static_cast<std::size_t>(c - '0');
  }
  if (v > limit) return false;
  *value = v;
  return true;
}

std::vector<std::string> splitWords(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

struct Header {
  Table table;
  std::size_t data_offset = 0;
};

Header parseHeader(const std::string& path, const std::string& bytes) {
  Header h;
  Table& t = h.table;
  std::vector<std::string> names, sizes, types, counts;
  bool have_width = false, have_height = false, have_points = false;
  std::size_t pos = 0;
  int line_no = 0;
  while (true) {
    if (pos >= bytes.size()) {
      throw Error(path, "header", "a PCD header ending in a DATA line", "end of file");
    }
    std::size_t eol = bytes.find('\n', pos);
    if (eol == std::string::npos) eol = bytes.size();
    std::string line = bytes.substr(pos, std::min<std::size_t>(eol - pos, 1 << 20));
    pos = std::min(eol + 1, bytes.size());
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::vector<std::string> words = splitWords(line);
    if (words.empty() || words[0][0] == '#') continue;
    const std::string& key = words[0];
    const std::string where = "header line " + std::to_string(line_no) + " (" + key + ")";
    const std::vector<std::string> args(words.begin() + 1, words.end());
    if (key == "VERSION" || key == "VIEWPOINT") {
      continue;
    } else if (key == "FIELDS" || key == "COLUMNS") {
      names = args;
    } else if (key == "SIZE") {
      sizes = args;
    } else if (key == "TYPE") {
      types = args;
    } else if (key == "COUNT") {
      counts = args;
    } else if (key == "WIDTH" || key == "HEIGHT" || key == "POINTS") {
      std::size_t v = 0;
      if (args.size() != 1 || !parseUnsigned(args[0], kMaxPoints, &v)) {
        throw Error(path, where, "one decimal number below 2^36", line);
      }
      if (key == "WIDTH") {
        t.width = static_cast<std::uint32_t>(std::min<std::size_t>(v, UINT32_MAX));
        have_width = v <= UINT32_MAX;
      } else if (key == "HEIGHT") {
        t.height = static_cast<std::uint32_t>(std::min<std::size_t>(v, UINT32_MAX));
        have_height = v <= UINT32_MAX;
      } else {
        t.points = v;
        have_points = true;
      }
    } else if (key == "DATA") {
      if (args.size() != 1 ||
          (args[0] != "ascii" && args[0] != "binary" && args[0] != "binary_compressed")) {
        throw Error(path, where, "ascii, binary or binary_compressed", line);
      }
      t.data_kind = args[0];
      break;
    } else {
      throw Error(path, "header line " + std::to_string(line_no), "a PCD header keyword",
                  key.substr(0, 40));
    }
  }
  h.data_offset = pos;

  if (names.empty()) throw Error(path, "FIELDS", "at least one field name", "none");
  if (names.size() > kMaxFields) {
    throw Error(path, "FIELDS", "at most 4096 fields", std::to_string(names.size()));
  }
  if (sizes.size() != names.size()) {
    throw Error(path, "SIZE", std::to_string(names.size()) + " values (one per field)",
                std::to_string(sizes.size()));
  }
  if (types.size() != names.size()) {
    throw Error(path, "TYPE", std::to_string(names.size()) + " values (one per field)",
                std::to_string(types.size()));
  }
  if (!counts.empty() && counts.size() != names.size()) {
    throw Error(path, "COUNT", std::to_string(names.size()) + " values (one per field)",
                std::to_string(counts.size()));
  }
  if (!have_width || !have_height) {
    throw Error(path, "WIDTH/HEIGHT", "both present, below 2^32",
                have_width ? "no HEIGHT" : "no WIDTH");
  }
  std::set<std::string> seen;
  for (std::size_t i = 0; i < names.size(); ++i) {
    Field f;
    f.name = names[i];
    if (f.name != "_" && !seen.insert(f.name).second) {
      throw Error(path, "FIELDS", "distinct field names", "\"" + f.name + "\" twice");
    }
    if (!parseUnsigned(sizes[i], 8, &f.size) ||
        (f.size != 1 && f.size != 2 && f.size != 4 && f.size != 8)) {
      throw Error(path, "SIZE of field " + f.name, "1, 2, 4 or 8", sizes[i]);
    }
    if (types[i] != "I" && types[i] != "U" && types[i] != "F") {
      throw Error(path, "TYPE of field " + f.name, "I, U or F", types[i]);
    }
    f.type = types[i][0];
    if (f.type == 'F' && f.size != 4 && f.size != 8) {
      throw Error(path, "SIZE of field " + f.name, "4 or 8 for TYPE F", sizes[i]);
    }
    if (!counts.empty() && (!parseUnsigned(counts[i], kMaxCount, &f.count) || f.count == 0)) {
      throw Error(path, "COUNT of field " + f.name, "a count in 1..65536", counts[i]);
    }
    f.offset = t.point_step;
    t.point_step += f.size * f.count;
    t.fields.push_back(f);
  }
  const std::size_t wh = std::size_t{t.width} * t.height;
  if (!have_points) t.points = wh;
  if (t.points != wh) {
    throw Error(path, "POINTS", "WIDTH x HEIGHT = " + std::to_string(wh), std::to_string(t.points));
  }
  if (t.points > kMaxPoints) throw Error(path, "POINTS", "below 2^36", std::to_string(t.points));
  return h;
}

double loadValueImpl(const std::uint8_t* p, const Field& f) {
  switch (f.type) {
    case 'F':
      if (f.size == 4) {
        float v;
        std::memcpy(&v, p, 4);
        return v;
      } else {
        double v;
        std::memcpy(&v, p, 8);
        return v;
      }
    case 'I':
      switch (f.size) {
        case 1:
          return static_cast<std::int8_t>(p[0]);
        case 2: {
          std::int16_t v;
          std::memcpy(&v, p, 2);
          return v;
        }
        case 4: {
          std::int32_t v;
          std::memcpy(&v, p, 4);
          return v;
        }
        default: {
          std::int64_t v;
          std::memcpy(&v, p, 8);
          return static_cast<double>(v);
        }
      }
    default:
      switch (f.size) {
        case 1:
          return p[0];
        case 2: {
          std::uint16_t v;
          std::memcpy(&v, p, 2);
          return v;
        }
        case 4: {
          std::uint32_t v;
          std::memcpy(&v, p, 4);
          return v;
        }
        default: {
          std::uint64_t v;
          std::memcpy(&v, p, 8);
          return static_cast<double>(v);
        }
      }
  }
}

// Stores an ascii value into its binary slot; false when it does not fit the field's type.
bool storeValueImpl(double v, const Field& f, std::uint8_t* p) {
  if (f.type == 'F') {
    if (f.size == 4) {
      const float x = static_cast<float>(v);
      std::memcpy(p, &x, 4);
    } else {
      std::memcpy(p, &v, 8);
    }
    return true;
  }
  if (!std::isfinite(v) || v != std::floor(v)) return false;
  const double lo = f.type == 'U' ? 0.0 : -std::ldexp(1.0, static_cast<int>(8 * f.size) - 1);
  const double hi = f.type == 'U' ? std::ldexp(1.0, static_cast<int>(8 * f.size)) - 1
                                  : std::ldexp(1.0, static_cast<int>(8 * f.size) - 1) - 1;
  if (v < lo || v > hi) return false;
  if (f.type == 'U') {
    const std::uint64_t u = static_cast<std::uint64_t>(v);
    std::memcpy(p, &u, f.size);  // little endian: the low bytes come first
  } else {
    const std::int64_t s = static_cast<std::int64_t>(v);
    std::memcpy(p, &s, f.size);
  }
  return true;
}

void readAscii(const std::string& path, const std::string& bytes, std::size_t pos, Table& t) {
  std::size_t values_per_point = 0;
  for (const Field& f : t.fields) values_per_point += f.count;
  // Each value takes at least one character and a separator: check before allocating.
  if (t.points > 0 && values_per_point > (bytes.size() - pos) / t.points) {
    throw Error(path, "DATA ascii", std::to_string(t.points) + " points",
                "a file too short for them (truncated, or a wrong POINTS)");
  }
  t.data.assign(t.points * t.point_step, 0);
  for (std::size_t i = 0; i < t.points; ++i) {
    // The next non-empty line.
    std::size_t eol;
    while (true) {
      if (pos >= bytes.size()) {
        throw Error(path, "point " + std::to_string(i), "a line of values",
                    "end of file (file has fewer points than POINTS)");
      }
      eol = bytes.find('\n', pos);
      if (eol == std::string::npos) eol = bytes.size();
      if (bytes.find_first_not_of(" \t\r", pos) < eol) break;
      pos = eol + 1;
    }
    const char* cursor = bytes.data() + pos;
    const char* line_end = bytes.data() + eol;
    std::uint8_t* row = t.data.data() + i * t.point_step;
    for (const Field& f : t.fields) {
      for (std::size_t k = 0; k < f.count; ++k) {
        while (cursor < line_end && (*cursor == ' ' || *cursor == '\t' || *cursor == '\r')) {
          ++cursor;
        }
        const std::string where = "point " + std::to_string(i) + " field " + f.name;
        if (cursor >= line_end) {
          throw Error(path, where, std::to_string(values_per_point) + " values on the line",
                      "fewer");
        }
        const char* token_end = cursor;
        while (token_end < line_end && *token_end != ' ' && *token_end != '\t' &&
               *token_end != '\r') {
          ++token_end;
        }
        const std::string token(cursor, token_end);
        char* parsed_end = nullptr;
        const double v = std::strtod(token.c_str(), &parsed_end);
        if (token.empty() || parsed_end != token.c_str() + token.size()) {
          throw Error(path, where, "a number", token.substr(0, 40));
        }
        if (!storeValueImpl(v, f, row + f.offset + k * f.size)) {
          throw Error(path, where,
                      std::string("a value of TYPE ") + f.type + " SIZE " + std::to_string(f.size),
                      token.substr(0, 40));
        }
        cursor = token_end;
      }
    }
    while (cursor < line_end && (*cursor == ' ' || *cursor == '\t' || *cursor == '\r')) ++cursor;
    if (cursor < line_end) {
      throw Error(path, "point " + std::to_string(i),
                  std::to_string(values_per_point) + " values on the line", "more");
    }
    pos = eol + 1;
  }
}

void readBinary(const std::string& path, const std::string& bytes, std::size_t pos, Table& t) {
  if (t.points > 0 && t.point_step > (bytes.size() - pos) / t.points) {
    throw Error(path, "DATA binary",
                std::to_string(t.points) + " points of " + std::to_string(t.point_step) + " bytes",
                std::to_string(bytes.size() - pos) + " bytes (truncated, or a wrong POINTS/SIZE)");
  }
  const std::size_t need = t.points * t.point_step;
  if (need > bytes.size() - pos) {
    throw Error(path, "DATA binary", std::to_string(need) + " bytes of points",
                std::to_string(bytes.size() - pos) + " (truncated, or a wrong POINTS/SIZE)");
  }
  t.data.assign(bytes.begin() + static_cast<std::ptrdiff_t>(pos),
                bytes.begin() + static_cast<std::ptrdiff_t>(pos + need));
}

void readCompressed(const std::string& path, const std::string& bytes, std::size_t pos, Table& t) {
  if (bytes.size() - pos < 8) {
    throw Error(path, "DATA binary_compressed", "two 32-bit sizes", "end of file");
  }
  std::uint32_t compressed = 0, uncompressed = 0;
  std::memcpy(&compressed, bytes.data() + pos, 4);
  std::memcpy(&uncompressed, bytes.data() + pos + 4, 4);
  pos += 8;
  if (t.points > 0 && t.point_step > UINT32_MAX / t.points) {
    throw Error(path, "DATA binary_compressed", "at most 4 GiB of points (32-bit sizes)",
                std::to_string(t.points) + " points of " + std::to_string(t.point_step) + " bytes");
  }
  const std::size_t need = t.points * t.point_step;
  if (uncompressed != need) {
    throw Error(path, "DATA binary_compressed uncompressed size",
                std::to_string(need) + " (POINTS x point size)", std::to_string(uncompressed));
  }
  if (compressed > bytes.size() - pos) {
    throw Error(path, "DATA binary_compressed compressed size",
                "at most the " + std::to_string(bytes.size() - pos) + " bytes left",
                std::to_string(compressed));
  }
  if (need > std::size_t{compressed} * kMaxLzfRatio + 1024) {
    throw Error(path, "DATA binary_compressed", "an uncompressed size LZF can reach",
                std::to_string(need) + " from " + std::to_string(compressed) + " bytes");
  }
  std::vector<std::uint8_t> columns(need);
  if (need > 0 && !lzfDecompress(reinterpret_cast<const std::uint8_t*>(bytes.data()) + pos,
                                 compressed, columns.data(), need)) {
    throw Error(path, "DATA binary_compressed", "valid LZF data", "corrupt data");
  }
  // Columns (all points of field 0, then field 1, ...) to rows.
  t.data.assign(need, 0);
  std::size_t column_start = 0;
  for (const Field& f : t.fields) {
    const std::size_t width = f.size * f.count;
    for (std::size_t i = 0; i < t.points; ++i) {
      std::memcpy(t.data.data() + i * t.point_step + f.offset,
                  columns.data() + column_start + i * width, width);
    }
    column_start += width * t.points;
  }
}

}  // namespace

double loadValue(const std::uint8_t* p, const Field& f) { return loadValueImpl(p, f); }

bool storeValue(double v, const Field& f, std::uint8_t* p) { return storeValueImpl(v, f, p); }

const Field* Table::find(const std::string& name) const {
  for (const Field& f : fields) {
    if (f.name == name) return &f;
  }
  return nullptr;
}

bool lzfDecompress(const std::uint8_t* in, std::size_t in_size, std::uint8_t* out,
                   std::size_t out_size) {
  std::size_t ip = 0, op = 0;
  while (ip < in_size) {
    const unsigned ctrl = in[ip++];
    if (ctrl < 32) {  // a literal run of ctrl + 1 bytes
      const std::size_t len = ctrl + 1;
      if (ip + len > in_size || op + len > out_size) return false;
      std::memcpy(out + op, in + ip, len);
      ip += len;
      op += len;
    } else {  // a back-reference: length (ctrl >> 5) + 2, distance ((ctrl & 31) << 8) + next + 1
      std::size_t len = ctrl >> 5;
      if (len == 7) {
        if (ip >= in_size) return false;
        len += in[ip++];
      }
      len += 2;
      if (ip >= in_size) return false;
      const std::size_t distance = ((ctrl & 31u) << 8) + in[ip++] + 1;
      if (distance > op || op + len > out_size) return false;
      for (std::size_t k = 0; k < len; ++k, ++op) out[op] = out[op - distance];  // may overlap
    }
  }
  return op == out_size;
}

Table readHeader(const std::string& path) {
  // Only the header: telling a Gaussian PCD from a semantic one must not read the points.
  return parseHeader(path, readFileStart(path, kMaxHeaderBytes)).table;
}

Table read(const std::string& path) {
  const std::string bytes = readWholeFile(path);
  Header h = parseHeader(path, bytes);
  Table& t = h.table;
  if (t.data_kind == "ascii") {
    readAscii(path, bytes, h.data_offset, t);
  } else if (t.data_kind == "binary") {
    readBinary(path, bytes, h.data_offset, t);
  } else {
    readCompressed(path, bytes, h.data_offset, t);
  }
  return std::move(h.table);
}

void write(const std::string& path, const Table& t) {
  std::ostringstream header;
  header << "# .PCD v0.7 - Point Cloud Data file format (written by sadsplat)\nVERSION 0.7\nFIELDS";
  for (const Field& f : t.fields) header << " " << f.name;
  header << "\nSIZE";
  for (const Field& f : t.fields) header << " " << f.size;
  header << "\nTYPE";
  for (const Field& f : t.fields) header << " " << f.type;
  header << "\nCOUNT";
  for (const Field& f : t.fields) header << " " << f.count;
  header << "\nWIDTH " << t.width << "\nHEIGHT " << t.height << "\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS "
         << t.points << "\nDATA binary\n";
  const std::string text = header.str();
  writeFileAtomically(path, [&](std::ostream& out) {
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.write(reinterpret_cast<const char*>(t.data.data()),
              static_cast<std::streamsize>(t.data.size()));
  });
}

}  // namespace pcd
}  // namespace io
}  // namespace sadsplat
