// sadsplat::Error: the one-line message form, with bytes from files escaped.
#include <gtest/gtest.h>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace {

TEST(Error, MessageNamesFileFieldExpectationAndFinding) {
  const Error e("a.ply", "vertex 3", "a number", "abc");
  EXPECT_STREQ(e.what(), "a.ply: vertex 3: expected a number, got abc");
  EXPECT_EQ(e.got(), "abc");
}

// Control characters from a file would reach the user's terminal: they are escaped, and the
// message stays one line.
TEST(Error, ControlCharactersAreEscaped) {
  const Error e("f\n.ply", "field\t1", "x", std::string("a\x1b[2Jb\x01\x7f\r", 9));
  EXPECT_STREQ(e.what(), "f\\n.ply: field\\t1: expected x, got a\\x1b[2Jb\\x01\\x7f\\r");
  EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
}

// Binary data (bytes that are not UTF-8) is escaped too; UTF-8 text is kept.
TEST(Error, InvalidUtf8IsEscapedValidUtf8Kept) {
  const Error e("Straße.ply", "f", "x",
                std::string("\xff\xfe"
                            "caf\xc3\xa9"
                            "\xc3",
                            8));
  EXPECT_STREQ(e.what(), "Straße.ply: f: expected x, got \\xff\\xfecaf\xc3\xa9\\xc3");
}

}  // namespace
}  // namespace sadsplat
