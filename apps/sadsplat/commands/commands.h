#pragma once
// The factories of the commands, one per file in this folder.

#include <memory>

#include "../command.h"

namespace sadsplat {
namespace cli {

std::unique_ptr<Command> makeInfoCommand();
std::unique_ptr<Command> makeSfmCommand();
std::unique_ptr<Command> makeImportCommand();
std::unique_ptr<Command> makePickViewsCommand();
std::unique_ptr<Command> makeConvertCommand();
std::unique_ptr<Command> makeExtractCommand();
std::unique_ptr<Command> makeTrainCommand();
std::unique_ptr<Command> makePseudoLabelsCommand();
std::unique_ptr<Command> makeEvalCommand();
std::unique_ptr<Command> makeRenderCommand();
std::unique_ptr<Command> makeOrthoCommand();
std::unique_ptr<Command> makeTilesCommand();
std::unique_ptr<Command> makeCompactCommand();
std::unique_ptr<Command> makeTableCommand();
std::unique_ptr<Command> makeDemoCommand();
std::unique_ptr<Command> makeSynthCommand();
#if SADSPLAT_HAVE_VIZ
std::unique_ptr<Command> makeViewCommand();
std::unique_ptr<Command> makeReportCommand();
#endif

}  // namespace cli
}  // namespace sadsplat
