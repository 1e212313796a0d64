#include "tools/command.hpp"

#include <csignal>
#include <cstdio>
#include <exception>
#include <map>
#include <utility>

namespace stvl::tools {
namespace {
std::atomic<bool> g_stop{false};
std::atomic<int> g_signal{0};
extern "C" void request_stop(int signal) {
  g_signal = signal;
  g_stop = true;
}

std::map<std::string, CommandSetup>& registry() {
  static std::map<std::string, CommandSetup> commands;
  return commands;
}
}  // namespace

const std::atomic<bool>* catch_stop_signals() {
  std::signal(SIGINT, request_stop);
  std::signal(SIGTERM, request_stop);
  return &g_stop;
}

int caught_signal() { return g_signal.load(); }

void add_bag_options(CLI::App& cmd, std::string& format, std::string& compression, std::string& topics) {
  cmd.add_option("--bag-format", format, "ros1 | ros2 (default: ros2 for a name ending in .mcap, ros1 otherwise)")
      ->check(CLI::IsMember({"ros1", "ros2"}));
  cmd.add_option("--bag-compression", compression,
                 "ROS 1: none (default) | bz2 | lz4; ROS 2: zstd (default) | lz4 | none")
      ->check(CLI::IsMember({"none", "bz2", "lz4", "zstd"}));
  cmd.add_option("--bag-topics", topics,
                 "Topics in the bag: all | default | a comma-separated list of topics and globs ('*'); default: all "
                 "for ROS 1, default for ROS 2 (everything but the full clouds */depth/points)");
}

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
