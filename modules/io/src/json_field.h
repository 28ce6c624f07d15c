#pragma once
// Typed access to a JSON document read from a file, for every JSON reader of sadsplat_io
// (transforms.json, LabelMe / COCO, georeference.json, classes.json, a .sog's meta.json): a value
// that is valid JSON but not what the reader expects (a missing member, a string where a number
// belongs, 1e400, 2^32 where an int belongs) ends as one sadsplat::Error naming the file and the
// field's path ("frames[3].fl_x"), never as a library exception.
#include <nlohmann/json.hpp>

#include <cstddef>
#include <string>
#include <vector>

namespace sadsplat {
namespace io {

/// \brief Parses JSON text; a syntax error or a number beyond double (1e400) is an Error naming
/// `origin`.
nlohmann::json parseJson(const std::string& text, const std::string& origin);

/// \brief Reads and parses a JSON file (requireRegularFile first).
nlohmann::json readJsonFile(const std::string& path);

/// \brief One value of a parsed JSON document with its file and its path inside the file.
class JsonField {
 public:
  /// \brief The document's root (field path "JSON").
  JsonField(const nlohmann::json& value, std::string file);
  JsonField(const nlohmann::json& value, std::string file, std::string field);

  const nlohmann::json& raw() const { return *value_; }
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }

  bool isNull() const { return value_->is_null(); }
  bool isObject() const { return value_->is_object(); }
  bool isArray() const { return value_->is_array(); }
  bool isString() const { return value_->is_string(); }
  bool isNumber() const { return value_->is_number(); }

  /// \brief Whether this is an object with `key` set to something other than null.
  bool has(const char* key) const;
  /// \brief The member `key` of this object; an Error when this is no object or `key` is missing.
  JsonField operator[](const char* key) const;
  /// \brief The member `key`, or a null field when absent (check with isNull()).
  JsonField optional(const char* key) const;
  /// \brief The elements of this array (an Error when it is none).
  std::vector<JsonField> elements() const;
  /// \brief The number of elements of this array (an Error when it is none).
  std::size_t size() const;
  /// \brief Element `index` of this array (an Error when it is none or too short).
  JsonField at(std::size_t index) const;

  /// \brief A finite number.
  double number() const;
  /// \brief A finite number in [min, max].
  double number(double min, double max) const;
  /// \brief An integer in [min, max] (1.0 is accepted, 1.5 and 2^32 for an int are not).
  long long integer(long long min, long long max) const;
  /// \brief A string.
  std::string text() const;
  /// \brief true or false.
  bool boolean() const;

  /// \brief Throws Error(file, field, expected, <this value, shortened>).
  [[noreturn]] void fail(const std::string& expected) const;
  /// \brief The value as short JSON text for a message ("missing" when absent).
  std::string shown() const;

 private:
  // The field path of member `key` ("frames[3].fl_x"; a root member is its key alone).
  std::string memberPath(const char* key) const;

  const nlohmann::json* value_;
  std::string file_;
  std::string field_;
};

}  // namespace io
}  // namespace sadsplat
