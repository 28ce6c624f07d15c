#include "sadsplat/common/error.h"

#include <utility>

namespace sadsplat {
namespace {

// The length of the valid UTF-8 sequence starting at text[i], or 0 if it is not one.
std::size_t utf8Length(const std::string& text, std::size_t i) {
  const auto c = static_cast<unsigned char>(text[i]);
  const std::size_t n = c >= 0xf0 && c <= 0xf4 ? 4 : c >= 0xe0 ? 3 : c >= 0xc2 && c < 0xe0 ? 2 : 0;
  if (n == 0 || i + n > text.size()) return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if ((static_cast<unsigned char>(text[i + k]) & 0xc0) != 0x80) return 0;
  }
  return n;
}

// Bytes that come from a file or a command line may hold control characters or binary data;
// printed raw they could rewrite the user's terminal or split the one-line message. Control
// characters and bytes that are not valid UTF-8 are shown escaped (\n, \x1b); UTF-8 text stays.
std::string escapeControl(const std::string& text) {
  static const char kHex[] = "0123456789abcdef";
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char ch = text[i];
    const auto c = static_cast<unsigned char>(ch);
    if (c >= 0x80) {
      const std::size_t n = utf8Length(text, i);
      if (n > 0) {
        out.append(text, i, n);
        i += n - 1;
      } else {
        out += "\\x";
        out += kHex[c >> 4];
        out += kHex[c & 15];
      }
    } else if (c == '\n') {
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
