#pragma once
// One `sadsplat` subcommand: its options and what it runs. main.cpp holds the table of them; each
// lives in commands/<name>.cpp (COLMAP's colmap.cc and its RunX functions are the model). A
// command parses, calls the library and prints: anything a C++ user could want is in a module.

#include <CLI/CLI.hpp>

#include <memory>
#include <vector>

namespace sadsplat {
namespace cli {

/// \brief What a command may need of the process beyond its options.
struct Invocation {
  int argc = 0;
  char** argv = nullptr;
};

class Command {
 public:
  virtual ~Command() = default;
  /// \brief Adds the subcommand and its options to `app`.
  virtual CLI::App* add(CLI::App& app) = 0;
  /// \brief Runs the parsed command; returns the exit status. Errors are sadsplat::Error.
  virtual int run(const Invocation& invocation) = 0;
};

/// \brief Every command of this build, in --help order.
std::vector<std::unique_ptr<Command>> allCommands();

}  // namespace cli
}  // namespace sadsplat
