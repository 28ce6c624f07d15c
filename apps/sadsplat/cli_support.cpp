#include "cli_support.h"

#include <unistd.h>

#include <csignal>
#include <cstdlib>
#include <stdexcept>
#include <vector>

#include "sadsplat/common/error.h"
#if SADSPLAT_HAVE_VIZ
#include "sadsplat/viz/display.h"
#endif

namespace sadsplat {
namespace cli {

std::atomic<bool> g_stop{false};

namespace {
extern "C" void requestStop(int) { g_stop = true; }
}  // namespace

void installStopHandlers() {
  std::signal(SIGINT, requestStop);
  std::signal(SIGTERM, requestStop);
}

void parseSize(const std::string& text, const std::string& flag, int* width, int* height) {
  const auto x = text.find('x');
  try {
    std::size_t used_w = 0, used_h = 0;
    if (x == std::string::npos) throw std::invalid_argument("no x");
    *width = std::stoi(text.substr(0, x), &used_w);
    *height = std::stoi(text.substr(x + 1), &used_h);
    if (used_w != x || used_h != text.size() - x - 1) throw std::invalid_argument("trailing");
  } catch (const std::exception&) {
    throw Error("<command line>", flag, "WIDTHxHEIGHT, e.g. 1280x720", text);
  }
}

std::vector<int> parseIndexList(const std::string& text, const std::string& flag) {
  std::vector<int> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = text.find(',', start);
    const std::string item = text.substr(start, comma - start);
    std::size_t used = 0;
    int value = -1;
    try {
      value = std::stoi(item, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (item.empty() || used != item.size() || value < 0)
      throw Error("<command line>", flag, "comma-separated view indices (0,7,28) or auto", text);
    out.push_back(value);
    if (comma == std::string::npos) return out;
    start = comma + 1;
  }
}

void rerunUnderXvfbIfHeadless(const Invocation& invocation) {
#if SADSPLAT_HAVE_VIZ
  if (viz::haveDisplay() || std::getenv("SADSPLAT_UNDER_XVFB") != nullptr) return;
  if (std::system("command -v xvfb-run >/dev/null 2>&1") != 0) return;  // requireDisplay says why
  setenv("SADSPLAT_UNDER_XVFB", "1", 1);
  std::vector<char*> args = {const_cast<char*>("xvfb-run"), const_cast<char*>("-a"),
                             const_cast<char*>("-s"),
                             const_cast<char*>("-screen 0 3840x2160x24 -nolisten tcp")};
  for (int i = 0; i < invocation.argc; ++i) args.push_back(invocation.argv[i]);
  args.push_back(nullptr);
  execvp("xvfb-run", args.data());  // returns only on failure: then the display error follows
#else
  (void)invocation;
#endif
}

}  // namespace cli
}  // namespace sadsplat
