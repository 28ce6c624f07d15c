#pragma once
// Small pieces several commands share: the stop flag of SIGINT/SIGTERM, "WxH" sizes, re-running
// a headless VTK job under Xvfb.

#include <atomic>
#include <string>
#include <vector>

#include "command.h"

namespace sadsplat {
namespace cli {

/// \brief Set by SIGINT / SIGTERM once installStopHandlers() ran: training stops after the
/// current iteration with a checkpoint.
extern std::atomic<bool> g_stop;
void installStopHandlers();

/// \brief "1280x720" -> width, height.
/// \throws sadsplat::Error naming `flag` otherwise
void parseSize(const std::string& text, const std::string& flag, int* width, int* height);

/// \brief "0,7,28" -> {0, 7, 28} (non-negative integers).
/// \throws sadsplat::Error naming `flag` otherwise
std::vector<int> parseIndexList(const std::string& text, const std::string& flag);

/// \brief VTK renders through X only on Debian: an offscreen job (a screenshot, a report, charts)
/// on a machine with no display runs itself again under xvfb-run when that is installed. Returns
/// only when no re-run was needed or possible (then VTK's own display error follows).
void rerunUnderXvfbIfHeadless(const Invocation& invocation);

}  // namespace cli
}  // namespace sadsplat
