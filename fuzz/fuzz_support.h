#pragma once
// libFuzzer harness support: a reader gets the input as a file (sadsplat's readers take paths);
// a sadsplat::Error is the expected answer to bad input, anything else aborts: an exception of
// another type is the "internal error" exit of the CLI, and a bug.
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace fuzz {

// A file of this process, rewritten with each input; the name keeps the reader's extension.
inline std::string inputFile(const std::string& name) {
  static const std::string dir = [] {
    std::string d = "/tmp/sadsplat_fuzz_" + std::to_string(::getpid());
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir + "/" + name;
}

inline void writeInput(const std::string& path, const std::uint8_t* data, std::size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

// The message of the last sadsplat::Error a target's reader gave ("" after a success): the
// corpus test checks the regression inputs' messages against fuzz/regressions/expected.tsv.
inline std::string& lastError() {
  static std::string message;
  return message;
}

// Runs `read`; a sadsplat::Error is fine, any other exception aborts with its message.
inline void expectOnlySadsplatErrors(const std::function<void()>& read) {
  lastError().clear();
  try {
    read();
  } catch (const Error& e) {
    lastError() = e.what();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "internal error (not a sadsplat::Error): %s\n", e.what());
    std::abort();
  }
}

}  // namespace fuzz
}  // namespace sadsplat
