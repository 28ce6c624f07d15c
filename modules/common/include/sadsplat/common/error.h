#pragma once
/// \file error.h
/// \brief The one exception type of sadsplat: every failure names the file, the field and what
/// was expected, so that a user can fix the input without reading code.

#include <stdexcept>
#include <string>

namespace sadsplat {

/// \brief Error raised for bad input, unreadable files and unusable configurations.
///
/// what() reads "<file>: <field>: expected <expected>[, got <got>]". The CLI catches it in
/// main(), prints what() and exits with a non-zero status.
class Error : public std::runtime_error {
 public:
  /// \param[in] file the file (or directory, or "<config>") the problem is in
  /// \param[in] field the field, element, property or line within the file
  /// \param[in] expected what a correct input has there
  /// \param[in] got what was found instead (required: a message says what it found)
  Error(std::string file, std::string field, std::string expected, std::string got);

  /// \brief The file the problem is in.
  const std::string& file() const { return file_; }
  /// \brief The field, property or line within the file.
  const std::string& field() const { return field_; }
  /// \brief What a correct input has there.
  const std::string& expected() const { return expected_; }
  /// \brief What was found instead (may be empty).
  const std::string& got() const { return got_; }

 private:
  std::string file_;
  std::string field_;
  std::string expected_;
  std::string got_;
};

}  // namespace sadsplat
