#include "sadsplat/common/error.h"

#include <utility>

namespace sadsplat {
namespace {

// Bytes that come from a file or a command line may hold control characters; printed raw they
// could rewrite the user's terminal or split the one-line message. They are shown escaped.
std::string escapeControl(const std::string& text) {
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  for (const char ch : text) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '\n') {
      out += "\\n";
    } else if (c == '\r') {
      out += "\\r";
    } else if (c == '\t') {
      out += "\\t";
    } else if (c < 0x20 || c == 0x7f) {
      out += "\\x";
      out += kHex[c >> 4];
      out += kHex[c & 15];
    } else {
      out += ch;
    }
  }
  return out;
}

std::string formatMessage(const std::string& file, const std::string& field,
                          const std::string& expected, const std::string& got) {
  std::string message =
      escapeControl(file) + ": " + escapeControl(field) + ": expected " + escapeControl(expected);
  if (!got.empty()) message += ", got " + escapeControl(got);
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
