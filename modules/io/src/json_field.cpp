#include "json_field.h"

#include <cmath>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"

namespace sadsplat {
namespace io {
namespace {

const nlohmann::json& nullValue() {
  static const nlohmann::json kNull;
  return kNull;
}

}  // namespace

nlohmann::json parseJson(const std::string& text, const std::string& origin) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    // parse_error for syntax; out_of_range (406) for a number beyond double such as 1e400.
    throw Error(origin, "JSON syntax", "valid JSON with numbers within double's range", e.what());
  }
}

nlohmann::json readJsonFile(const std::string& path) {
  requireRegularFile(path);
  return parseJson(readWholeFile(path), path);
}

JsonField::JsonField(const nlohmann::json& value, std::string file)
    : value_(&value), file_(std::move(file)), field_("JSON") {}

JsonField::JsonField(const nlohmann::json& value, std::string file, std::string field)
    : value_(&value), file_(std::move(file)), field_(std::move(field)) {}

std::string JsonField::shown() const {
  if (value_ == &nullValue()) return "missing";
  std::string s = value_->dump(-1, ' ', true, nlohmann::json::error_handler_t::replace);
  if (s.size() > 60) s = s.substr(0, 57) + "...";
  return s;
}

void JsonField::fail(const std::string& expected) const {
  throw Error(file_, field_, expected, shown());
}

bool JsonField::has(const char* key) const {
  if (!value_->is_object()) return false;
  const auto it = value_->find(key);
  return it != value_->end() && !it->is_null();
}

std::string JsonField::memberPath(const char* key) const {
  return field_ == "JSON" ? std::string(key) : field_ + "." + key;
}

JsonField JsonField::operator[](const char* key) const {
  if (!value_->is_object()) fail(std::string("an object with \"") + key + "\"");
  const std::string path = memberPath(key);
  const auto it = value_->find(key);
  if (it == value_->end()) throw Error(file_, path, "a value", "missing");
  return JsonField(*it, file_, path);
}

JsonField JsonField::optional(const char* key) const {
  const std::string path = memberPath(key);
  if (!value_->is_object()) fail(std::string("an object"));
  const auto it = value_->find(key);
  return JsonField(it == value_->end() ? nullValue() : *it, file_, path);
}

std::vector<JsonField> JsonField::elements() const {
  if (!value_->is_array()) fail("an array");
  std::vector<JsonField> out;
  out.reserve(value_->size());
  for (std::size_t i = 0; i < value_->size(); ++i) {
    out.emplace_back((*value_)[i], file_, field_ + "[" + std::to_string(i) + "]");
  }
  return out;
}

std::size_t JsonField::size() const {
  if (!value_->is_array()) fail("an array");
  return value_->size();
}

JsonField JsonField::at(std::size_t index) const {
  if (!value_->is_array() || index >= value_->size()) {
    fail("an array of at least " + std::to_string(index + 1) + " elements");
  }
  return JsonField((*value_)[index], file_, field_ + "[" + std::to_string(index) + "]");
}

double JsonField::number() const {
  if (!value_->is_number()) fail("a number");
  const double d = value_->get<double>();
  if (!std::isfinite(d)) fail("a finite number");
  return d;
}

double JsonField::number(double min, double max) const {
  const double d = number();
  if (!(d >= min && d <= max)) {
    fail("a number in [" + nlohmann::json(min).dump() + ", " + nlohmann::json(max).dump() + "]");
  }
  return d;
}

long long JsonField::integer(long long min, long long max) const {
  const std::string expected =
      "an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
  if (value_->is_number_integer()) {
    if (value_->is_number_unsigned()) {
      const auto u = value_->get<unsigned long long>();
      if (max < 0 || u > static_cast<unsigned long long>(max)) fail(expected);
      return static_cast<long long>(u);
    }
    const auto v = value_->get<long long>();
    if (v < min || v > max) fail(expected);
    return v;
  }
  if (!value_->is_number()) fail(expected);
  const double d = value_->get<double>();
  // Doubles beyond +-2^53 are not exact integers; the range check comes first so the cast is defined.
  if (!(d >= static_cast<double>(min) && d <= static_cast<double>(max)) || d != std::floor(d) ||
      std::fabs(d) >= 9.2e18) {
    fail(expected);
  }
  return static_cast<long long>(d);
}

std::string JsonField::text() const {
  if (!value_->is_string()) fail("a string");
  return value_->get<std::string>();
}

bool JsonField::boolean() const {
  if (!value_->is_boolean()) fail("true or false");
  return value_->get<bool>();
}

}  // namespace io
}  // namespace sadsplat
