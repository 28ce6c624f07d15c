#pragma once
// The PLY container format (header, ascii / binary values, element skipping), shared by the
// 3DGS Gaussian PLY and the plain semantic PLY readers. Every count in a header is checked
// against the bytes present before it drives an allocation or a loop.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace io {
namespace ply {

enum class PlyType { kInt8, kUInt8, kInt16, kUInt16, kInt32, kUInt32, kFloat32, kFloat64 };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::kFloat32;
  bool is_list = false;
  PlyType count_type = PlyType::kUInt8;
};

struct PlyElement {
  std::string name;
  std::size_t count = 0;
  std::vector<PlyProperty> properties;
};

enum class PlyFormat { kAscii, kBinaryLittleEndian, kBinaryBigEndian };

struct PlyHeader {
  PlyFormat format = PlyFormat::kBinaryLittleEndian;
  std::string format_name;
  std::vector<PlyElement> elements;
  std::size_t data_offset = 0;
};

inline bool parseType(const std::string& s, PlyType* type) {
  static const std::pair<const char*, PlyType> kNames[] = {
      {"char", PlyType::kInt8},      {"int8", PlyType::kInt8},       {"uchar", PlyType::kUInt8},
      {"uint8", PlyType::kUInt8},    {"short", PlyType::kInt16},     {"int16", PlyType::kInt16},
      {"ushort", PlyType::kUInt16},  {"uint16", PlyType::kUInt16},   {"int", PlyType::kInt32},
      {"int32", PlyType::kInt32},    {"uint", PlyType::kUInt32},     {"uint32", PlyType::kUInt32},
      {"float", PlyType::kFloat32},  {"float32", PlyType::kFloat32}, {"double", PlyType::kFloat64},
      {"float64", PlyType::kFloat64}};
  for (const auto& [name, t] : kNames) {
    if (s == name) {
      *type = t;
      return true;
    }
  }
  return false;
}

inline std::size_t typeSize(PlyType t) {
  switch (t) {
    case PlyType::kInt8:
    case PlyType::kUInt8:
      return 1;
    case PlyType::kInt16:
    case PlyType::kUInt16:
      return 2;
    case PlyType::kInt32:
    case PlyType::kUInt32:
    case PlyType::kFloat32:
      return 4;
    case PlyType::kFloat64:
      return 8;
  }
  return 0;
}

// A count from the header: decimal digits only ("0x28" and "1abc" are not counts), and small
// enough that multiplying it by a record size cannot overflow. Whether the file holds that many
// items is checked against its size before anything is allocated (checkElementFits).
inline bool parseCount(const std::string& text, std::size_t* count) {
  constexpr std::size_t kMaxCount = std::size_t{1} << 40;
  if (text.empty() || text.size() > 13) return false;
  std::size_t value = 0;
  for (const char c : text) {
    if (c < '0' || c > '9') return false;
    value = value * 10 + static_cast<std::size_t>(c - '0');
  }
  if (value >= kMaxCount) return false;
  *count = value;
  return true;
}

// The fewest bytes one item of `element` can take: the fixed part of a binary record (list items
// counted as empty), or in ascii one character per value and the line end.
inline std::size_t minItemBytes(const PlyElement& element, PlyFormat format) {
  if (format == PlyFormat::kAscii) return element.properties.size() + 1;
  std::size_t bytes = 0;
  for (const PlyProperty& p : element.properties) {
    bytes += typeSize(p.is_list ? p.count_type : p.type);
  }
  return bytes;
}

inline PlyHeader parseHeader(const std::string& path, const std::string& bytes) {
  if (bytes.compare(0, 4, "ply\n") != 0 && bytes.compare(0, 5, "ply\r\n") != 0) {
    throw Error(path, "magic", "a PLY file starting with \"ply\"",
                bytes.empty() ? "an empty file" : "other bytes");
  }
  PlyHeader header;
  std::size_t pos = 0;
  bool have_format = false;
  int line_no = 0;
  while (true) {
    const std::size_t eol = bytes.find('\n', pos);
    if (eol == std::string::npos) throw Error(path, "header", "an \"end_header\" line", "EOF");
    std::string line = bytes.substr(pos, eol - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = eol + 1;
    ++line_no;
    std::istringstream words(line);
    std::string keyword;
    words >> keyword;
    const std::string where = "header line " + std::to_string(line_no);
    if (keyword == "ply" || keyword == "comment" || keyword == "obj_info" || keyword.empty()) {
      continue;
    }
    if (keyword == "end_header") break;
    if (keyword == "format") {
      std::string name, version;
      words >> name >> version;
      if (name == "ascii") {
        header.format = PlyFormat::kAscii;
      } else if (name == "binary_little_endian") {
        header.format = PlyFormat::kBinaryLittleEndian;
      } else if (name == "binary_big_endian") {
        header.format = PlyFormat::kBinaryBigEndian;
      } else {
        throw Error(path, where + " (format)", "ascii, binary_little_endian or binary_big_endian",
                    name);
      }
      header.format_name = name;
      have_format = true;
    } else if (keyword == "element") {
      PlyElement element;
      std::string count_text, extra;
      words >> element.name >> count_text >> extra;
      if (element.name.empty() || !parseCount(count_text, &element.count) || !extra.empty()) {
        throw Error(path, where + " (element)",
                    "\"element <name> <count>\" with a decimal count below 2^40", line);
      }
      header.elements.push_back(element);
    } else if (keyword == "property") {
      if (header.elements.empty()) {
        throw Error(path, where + " (property)", "a property after an element line", line);
      }
      PlyProperty property;
      std::string type;
      words >> type;
      if (type == "list") {
        std::string count_type, item_type;
        words >> count_type >> item_type >> property.name;
        property.is_list = true;
        if (!parseType(count_type, &property.count_type) || !parseType(item_type, &property.type)) {
          throw Error(path, where + " (property list)", "known PLY scalar types", line);
        }
      } else {
        words >> property.name;
        if (!parseType(type, &property.type)) {
          throw Error(path, where + " (property " + property.name + ")",
                      "a PLY scalar type (char uchar short ushort int uint float double)", type);
        }
      }
      if (property.name.empty()) throw Error(path, where, "a property name", line);
      header.elements.back().properties.push_back(property);
    } else {
      throw Error(path, where, "a PLY header keyword", keyword);
    }
  }
  if (!have_format) throw Error(path, "header", "a \"format\" line", "none");
  header.data_offset = pos;
  return header;
}

// Reads the values of the data section one after the other, ascii or binary of either order.
class ValueDecoder {
 public:
  ValueDecoder(const std::string& path, const std::string& bytes, std::size_t pos, PlyFormat format)
      : path_(path), bytes_(bytes), pos_(pos), format_(format) {}

  double next(PlyType type, const std::string& what) {
    if (format_ == PlyFormat::kAscii) return nextAscii(what);
    const std::size_t size = typeSize(type);
    if (pos_ + size > bytes_.size()) {
      throw Error(path_, what, "more data (file is truncated)", "end of file");
    }
    unsigned char raw[8];
    std::memcpy(raw, bytes_.data() + pos_, size);
    pos_ += size;
    if (format_ == PlyFormat::kBinaryBigEndian) {
      for (std::size_t i = 0; i < size / 2; ++i) std::swap(raw[i], raw[size - 1 - i]);
    }
    switch (type) {
      case PlyType::kInt8:
        return static_cast<double>(static_cast<std::int8_t>(raw[0]));
      case PlyType::kUInt8:
        return static_cast<double>(raw[0]);
      case PlyType::kInt16:
        return load<std::int16_t>(raw);
      case PlyType::kUInt16:
        return load<std::uint16_t>(raw);
      case PlyType::kInt32:
        return load<std::int32_t>(raw);
      case PlyType::kUInt32:
        return load<std::uint32_t>(raw);
      case PlyType::kFloat32:
        return load<float>(raw);
      case PlyType::kFloat64:
        return load<double>(raw);
    }
    return 0.0;
  }

  /// Bytes not yet read.
  std::size_t bytesLeft() const { return bytes_.size() - pos_; }
  /// Skips `n` bytes of binary data (checked by the caller).
  void skipBytes(std::size_t n) { pos_ += n; }

  // Skips to the next line in ascii files (one element item per line).
  void endItem() {
    if (format_ != PlyFormat::kAscii) return;
    while (pos_ < bytes_.size() && bytes_[pos_] != '\n') ++pos_;
    if (pos_ < bytes_.size()) ++pos_;
  }

 private:
  template <typename T>
  static double load(const unsigned char* raw) {
    T v;
    std::memcpy(&v, raw, sizeof(T));
    return static_cast<double>(v);
  }

  double nextAscii(const std::string& what) {
    while (pos_ < bytes_.size() && (bytes_[pos_] == ' ' || bytes_[pos_] == '\t')) ++pos_;
    if (pos_ >= bytes_.size() || bytes_[pos_] == '\n' || bytes_[pos_] == '\r') {
      throw Error(path_, what, "a number (line is short or file is truncated)", "end of line");
    }
    const char* begin = bytes_.data() + pos_;
    char* end = nullptr;
    const double v = std::strtod(begin, &end);
    if (end == begin) {
      throw Error(path_, what, "a number",
                  std::string(begin, std::min<std::size_t>(16, bytes_.size() - pos_)));
    }
    pos_ += static_cast<std::size_t>(end - begin);
    return v;
  }

  const std::string& path_;
  const std::string& bytes_;
  std::size_t pos_;
  PlyFormat format_;
};

// Throws unless the bytes left can hold `element.count` items of the element: no count from a
// header is used to allocate or to loop before this check.
inline void checkElementFits(const std::string& path, const ValueDecoder& decoder,
                             const PlyElement& element, PlyFormat format) {
  const std::size_t need = element.count * minItemBytes(element, format);
  if (need > decoder.bytesLeft()) {
    throw Error(
        path, "element " + element.name,
        std::to_string(element.count) + " items (at least " + std::to_string(need) + " bytes)",
        "a file with " + std::to_string(decoder.bytesLeft()) +
            " bytes left (truncated, or a wrong count in the header)");
  }
}

inline void skipElement(const std::string& path, ValueDecoder& decoder, const PlyElement& element,
                        PlyFormat format) {
  checkElementFits(path, decoder, element, format);
  bool has_list = false;
  for (const PlyProperty& p : element.properties) has_list = has_list || p.is_list;
  if (format != PlyFormat::kAscii && !has_list) {
    decoder.skipBytes(element.count * minItemBytes(element, format));
    return;
  }
  for (std::size_t i = 0; i < element.count; ++i) {
    const std::string what = "element " + element.name + " item " + std::to_string(i);
    for (const PlyProperty& p : element.properties) {
      if (p.is_list) {
        const double n = decoder.next(p.count_type, what);
        const std::size_t item_bytes = format == PlyFormat::kAscii ? 2 : typeSize(p.type);
        if (!(n >= 0) ||
            n * static_cast<double>(item_bytes) > static_cast<double>(decoder.bytesLeft())) {
          throw Error(path, what + " list " + p.name, "a length the file can hold",
                      std::to_string(n));
        }
        for (std::size_t k = 0; k < static_cast<std::size_t>(n); ++k) decoder.next(p.type, what);
      } else {
        decoder.next(p.type, what);
      }
    }
    decoder.endItem();
  }
}

}  // namespace ply
}  // namespace io
}  // namespace sadsplat
