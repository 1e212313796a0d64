#include "tools/command.hpp"

#include <cstdio>
#include <exception>
#include <map>
#include <utility>

namespace stvl::tools {
namespace {
std::map<std::string, CommandSetup>& registry() {
  static std::map<std::string, CommandSetup> commands;
  return commands;
}
}  // namespace

CommandRegistration::CommandRegistration(std::string name, CommandSetup setup) {
  registry().emplace(std::move(name), std::move(setup));
}
}  // namespace stvl::tools

int main(int argc, char** argv) {
  using namespace stvl::tools;
  CLI::App app{"stvl-bench: a headless test bench for depth-camera spatio-temporal voxel mapping"};
  app.require_subcommand(1);
  std::map<std::string, CommandRun> runs;
  for (auto& [name, setup] : registry()) runs.emplace(name, setup(app));
  if (argc > 1 && argv[1][0] != '-' && !runs.count(argv[1])) {
    std::fprintf(stderr, "stvl-bench: unknown subcommand '%s' (see stvl-bench --help)\n", argv[1]);
    return kExitBadInput;
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? kExitOk : kExitBadInput;
  }
  try {
    for (const auto* sub : app.get_subcommands()) return runs.at(sub->get_name())();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "stvl-bench: error: %s\n", e.what());
    return kExitBadInput;
  }
  return kExitBadInput;
}
