#include "sadsplat/common/error.h"

#include <utility>

namespace sadsplat {
namespace {

std::string formatMessage(const std::string& file, const std::string& field,
                          const std::string& expected, const std::string& got) {
  std::string message = file + ": " + field + ": expected " + expected;
  if (!got.empty()) message += ", got " + got;
  return message;
}

}  // namespace

Error::Error(std::string file, std::string field, std::string expected, std::string got)
    : std::runtime_error(formatMessage(file, field, expected, got)),
      file_(std::move(file)),
      field_(std::move(field)),
      expected_(std::move(expected)),
      got_(std::move(got)) {}

}  // namespace sadsplat
