// The sadsplat command line: a table of commands (commands/<name>.cpp), each parsing its options
// and calling the library. Errors of type sadsplat::Error become one message on stderr and exit
// status 1; usage errors exit 2; an interrupted training 130; anything else 3.
#include <CLI/CLI.hpp>

#include <iostream>

#include "command.h"
#include "commands/commands.h"
#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/cpu_threads.h"
#include "sadsplat/pipeline/train_run.h"

namespace sadsplat {
namespace cli {

std::vector<std::unique_ptr<Command>> allCommands() {
  std::vector<std::unique_ptr<Command>> commands;
  commands.push_back(makeInfoCommand());
  commands.push_back(makeSfmCommand());
  commands.push_back(makeImportCommand());
  commands.push_back(makePickViewsCommand());
  commands.push_back(makeConvertCommand());
  commands.push_back(makeExtractCommand());
  commands.push_back(makeTrainCommand());
  commands.push_back(makePseudoLabelsCommand());
  commands.push_back(makeEvalCommand());
  commands.push_back(makeRenderCommand());
  commands.push_back(makeOrthoCommand());
  commands.push_back(makeTilesCommand());
  commands.push_back(makeCompactCommand());
  commands.push_back(makeTableCommand());
  commands.push_back(makeDemoCommand());
  commands.push_back(makeSynthCommand());
#if SADSPLAT_HAVE_VIZ
  commands.push_back(makeViewCommand());
  commands.push_back(makeReportCommand());
#endif
  return commands;
}

}  // namespace cli
}  // namespace sadsplat

int main(int argc, char** argv) {
  using namespace sadsplat;
  CLI::App app{"sadsplat " SADSPLAT_VERSION
               ": compact semantic 3D Gaussian Splatting for aerial scenes, as PCL clouds"};
  app.require_subcommand(1);
  const auto commands = cli::allCommands();
  std::vector<CLI::App*> subcommands;
  for (const auto& command : commands) subcommands.push_back(command->add(app));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help / --version print and succeed; every usage error is one line and exit status 2
    // (CLI11's own codes vary by error kind, and it prints two lines).
    if (e.get_exit_code() == 0) return app.exit(e);
    std::cerr << "sadsplat: usage error: " << e.what() << " (see sadsplat --help)\n";
    return 2;
  }
  gaussians::setCpuThreads();
  try {
    for (std::size_t i = 0; i < commands.size(); ++i) {
      if (*subcommands[i]) return commands[i]->run({argc, argv});
    }
  } catch (const pipeline::TrainingInterrupted& e) {
    std::cerr << "\nsadsplat: interrupted: " << e.what() << "\n";
    return 130;
  } catch (const Error& e) {
    std::cerr << "sadsplat: error: " << e.what() << "\n";
    return 1;
  } catch (const std::exception& e) {
    std::cerr << "sadsplat: internal error: " << e.what() << "\n";
    return 3;
  }
  return 0;
}
