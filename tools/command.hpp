#pragma once
// Subcommands of `stvl-bench` register themselves from their own cmd_*.cpp file:
//
//   const stvl::tools::CommandRegistration kRender("render", [](CLI::App& app) {
//     auto* cmd = app.add_subcommand("render", "...");
//     auto options = std::make_shared<RenderOptions>();
//     cmd->add_option("--world", options->world_path)->required();
//     return [options] { return run_render(*options); };
//   });
//
// The returned function runs when the subcommand is chosen; its value is the process exit code
// (kExitOk, kExitCheckFailed). Bad input is reported by throwing; main() prints it and exits with kExitBadInput.
#include <CLI/CLI.hpp>

#include <atomic>
#include <functional>
#include <string>

namespace stvl::tools {

constexpr int kExitOk = 0;
constexpr int kExitCheckFailed = 1;
constexpr int kExitBadInput = 2;

// SIGINT and SIGTERM from here on set the returned flag, which the long commands (run, replay) poll between
// frames; caught_signal() is the last one caught (0: none), for the exit code 128 + signal.
const std::atomic<bool>* catch_stop_signals();
int caught_signal();

using CommandRun = std::function<int()>;
using CommandSetup = std::function<CommandRun(CLI::App& app)>;

// --bag-format, --bag-compression and --bag-topics, the bag options `run` and `replay` share (--bag itself
// says what each command writes).
void add_bag_options(CLI::App& cmd, std::string& format, std::string& compression, std::string& topics);

struct CommandRegistration {
  CommandRegistration(std::string name, CommandSetup setup);
};

}  // namespace stvl::tools
