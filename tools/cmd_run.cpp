// stvl-bench run [SCENARIO.yaml] [--out DIR] [--bag FILE] ...: one scenario end to end.
#include <cstdio>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/staged_directory.hpp"
#include "config/ros_binding.hpp"
#include "config/ros_nav2_layer.hpp"
#include "config/timing_lint.hpp"
#include "recording/bag_writer.hpp"
#include "report/report.hpp"
#include "run/runner.hpp"
#include "run/shared_drive.hpp"
#include "sim/urdf_robot.hpp"
#include "tools/command.hpp"

namespace stvl::tools {
using namespace stvl::config;
using namespace stvl::run;
using namespace stvl::report;
namespace {

// A seed is a decimal integer in [0, 2^64 - 1]; CLI11 alone would saturate larger values silently.
std::string seed_error(std::string& text) {
  const bool digits = !text.empty() && text.find_first_not_of("0123456789") == std::string::npos;
  if (!digits) return "expected a non-negative integer, got '" + text + "'";
  try {
    std::stoull(text);
  } catch (const std::out_of_range&) {
    return "'" + text + "' exceeds the largest seed, 18446744073709551615";
  }
  return {};
}

struct RunCommandOptions {
  std::string scenario;
  std::string out_dir;
  std::string bag;
  std::string bag_compression, bag_format, bag_topics;
  bool no_progress = false;
  bool profile = false;
  ScenarioOverrides overrides;
  std::vector<std::string> sets;
  std::string noise;
  bool require_path = false;
  bool no_run_ahead = false;
  std::vector<std::string> twins;  // --twin OUT;KEY=VALUE;...
};

// What the scenario's URDF robot gave: notices, the robot, its drive and footprint.
void print_urdf_robot(const Scenario& scenario) {
  const auto& robot = scenario.pipeline.urdf_robot;
  if (!robot) return;
  for (const auto& notice : robot->notices) std::printf("notice: %s\n", notice.c_str());
  std::printf("robot: %s from %s (base %s, %.2f kg; wheels %s: %s and %s, radius %.3f m, track %.3f m)\n",
              robot->urdf.name.c_str(), robot->config.urdf.c_str(), robot->urdf.root.c_str(), robot->mass_kg,
              robot->wheels.named ? "named" : "found", robot->wheels.left_joint.c_str(),
              robot->wheels.right_joint.c_str(), robot->wheels.radius_m, robot->wheels.track_width_m);
  std::printf("drive: %s (%s)\n", sim::to_string(robot->drive).c_str(), robot->drive_reason.c_str());
  std::printf("footprint: %s\n", scenario.footprint_source.empty() ? "none" : scenario.footprint_source.c_str());
}

// The linter's findings on the scenario's ROS parameter file, with the FOV of the camera each source is bound to.
void print_lint_findings(const Scenario& scenario) {
  // The closed loop's servers: plugins not modelled and what stands in (the run goes on).
  for (const auto& f : scenario.navigation_findings) std::printf("lint: %s\n", format_finding(f).c_str());
  // Camera timing against the layer's parameters (issue 43).
  for (const auto& f : lint_timing(scenario)) std::printf("lint: %s\n", format_finding(f).c_str());
  const auto& ros = scenario.ros_params;
  if (!ros) return;
  const auto findings =
      scenario.pipeline.layer_type != layer::LayerType::kStvl
          ? lint_ros_nav2_layer(ros->path, ros->layer, ros->costmap)
          : lint_ros_stvl_layer(ros->path, ros->layer, ros->costmap, bound_cameras(scenario.pipeline));
  for (const auto& f : findings) std::printf("lint: %s\n", format_finding(f).c_str());
  if (!findings.empty())
    std::printf("lint: %zu finding%s on %s (stvl-bench lint %s)\n", findings.size(), findings.size() == 1 ? "" : "s",
                ros->path.c_str(), ros->path.c_str());
}

// An interrupted run leaves --out as it was and its partial outputs beside it; the exit code is 128 + signal.
int abandon_interrupted_run(const RunCommandOptions& o, const RunOptions& options, const RunResult& result,
                            StagedDirectory& staged) {
  const std::string incomplete = staged.final_path().string() + ".incomplete";
  staged.abandon("interrupted by signal " + std::to_string(caught_signal()) + " after " +
                 std::to_string(result.frames) + " frames");
  std::string bag = o.bag;
  if (!bag.empty() && options.bag_path != o.bag)  // it moved with the partial outputs
    bag = (incomplete / std::filesystem::path(options.bag_path).lexically_relative(staged.path())).string();
  const bool ros2 = !bag.empty() && recording::parse_bag_format(o.bag_format, o.bag) == recording::BagFormat::kRos2;
  const std::string active = bag.empty() ? "" : (ros2 ? recording::ros2_bag_folder(bag) : bag) + ".active";
  std::error_code error;  // nothing written before the signal: no partial output to point at
  const std::string partial =
      std::filesystem::exists(incomplete, error) ? "the partial output in " + incomplete : "nothing written yet";
  std::fprintf(stderr,
               "stvl-bench: interrupted by signal %d after %zu frames; no result written (%s left as it was, %s)%s\n",
               caught_signal(), result.frames, staged.final_path().c_str(), partial.c_str(),
               active.empty() ? "" : (", the bag stays as " + active).c_str());
  return 128 + caught_signal();
}

// The profile when asked for, each check, and one line of the run's figures.
void print_run_summary(const RunCommandOptions& o, const Scenario& scenario, const RunResult& result,
                       const std::string& out_dir) {
  if (o.profile) std::printf("%s", profile_table(result).c_str());
  for (const auto& c : result.checks)
    std::printf("%s %-24s %s\n", !c.evaluated ? "SKIP" : c.passed ? "PASS" : "FAIL", c.name.c_str(), c.message.c_str());
  const auto& m = result.evaluation.mean;
  char quality[96] = "map quality not evaluated (no evaluation after the recall window)";
  if (m.snapshots > 0 && result.evaluation.voxels_3d)
    std::snprintf(quality, sizeof quality, "F1 %.3f (P %.3f R %.3f)", m.f1, m.precision, m.recall);
  else if (m.snapshots > 0)  // a layer without voxels (nav2's ObstacleLayer): its costmap's figures
    std::snprintf(quality, sizeof quality, "no voxels, costmap P %.3f R %.3f", m.costmap_precision, m.costmap_recall);
  std::printf("%s: %zu frames, %.1f s simulated, real-time factor %.2f, %s, outputs in %s\n", scenario.name.c_str(),
              result.frames, result.sim_time_s, result.real_time_factor, quality, out_dir.c_str());
}

// The scenario with the run's --sets and then `extra_sets`, and the overrides; prints the URDF robot and the lint
// findings when asked. Returns the scenario's own duration (before --duration) in `scenario_duration_s`.
Scenario load_run_scenario(const RunCommandOptions& o, const std::vector<std::string>& extra_sets, bool print,
                           double& scenario_duration_s) {
  std::vector<std::string> sets = o.sets;
  sets.insert(sets.end(), extra_sets.begin(), extra_sets.end());
  Scenario scenario = load_scenario(o.scenario.empty() ? default_scenario_path() : o.scenario, sets);
  ScenarioOverrides overrides = o.overrides;
  if (!o.noise.empty()) {
    if (o.noise != "on" && o.noise != "off")
      throw std::invalid_argument("--noise must be on or off, got '" + o.noise + "'");
    overrides.noise = o.noise == "on";
  }
  if (print) print_urdf_robot(scenario);
  scenario_duration_s = scenario.duration_s;
  apply_overrides(scenario, overrides);
  if (print) print_lint_findings(scenario);
  return scenario;
}

// The run's options for one output folder (staged: written whole or not at all); the bag for the first run only.
RunOptions run_options(const RunCommandOptions& o, const Scenario& scenario, double scenario_duration_s,
                       StagedDirectory& staged, bool first) {
  RunOptions options;
  options.out_dir = staged.path().string();
  if (first) {
    options.bag_path = o.bag.empty() ? std::string() : staged.redirect(o.bag).string();
    options.bag_compression = o.bag_compression;
    options.bag_format = o.bag_format;
    options.bag_topics = o.bag_topics;
  }
  options.progress = first && !o.no_progress;
  options.stop_requested = catch_stop_signals();
  if (scenario.duration_s < scenario_duration_s) options.cut_short_from_s = scenario_duration_s;
  options.require_path = o.require_path;
  options.run_ahead = !o.no_run_ahead;
  return options;
}

// The runs: one, or the run and its twins on one drive (one after another where the drive cannot be shared).
std::vector<RunResult> run_all(const std::vector<Scenario>& scenarios, const std::vector<RunOptions>& options) {
  if (scenarios.size() == 1) return {run_scenario(scenarios.front(), options.front())};
  if (can_share_drive(scenarios.front())) return run_twins(scenarios, options);
  std::printf(
      "notice: --twin: a closed-loop or timed drive depends on each run's layer; the twins run one after "
      "another\n");
  std::vector<RunResult> results;
  for (std::size_t i = 0; i < scenarios.size(); ++i) {
    results.push_back(run_scenario(scenarios[i], options[i]));
    if (results.back().interrupted) break;
  }
  return results;
}

int run(const RunCommandOptions& o) {
  std::vector<TwinSpec> twins{{o.out_dir, {}}};
  for (const auto& text : o.twins) twins.push_back(run::parse_twin(text));
  std::vector<Scenario> scenarios;
  double scenario_duration_s = 0;
  for (std::size_t i = 0; i < twins.size(); ++i) {
    scenarios.push_back(load_run_scenario(o, twins[i].sets, i == 0, scenario_duration_s));
    if (i == 0 && twins[0].out_dir.empty()) twins[0].out_dir = "out/" + scenarios[0].name;
    for (std::size_t j = 0; j < i; ++j)
      if (!folders_apart(twins[i].out_dir, twins[j].out_dir))
        throw std::invalid_argument("--twin: two runs would write " + twins[i].out_dir + " (with " + twins[j].out_dir +
                                    "): each needs a folder of its own, neither inside the other");
  }
  check_bag_outside_outputs(twins[0].out_dir, o.bag, o.bag_format);  // before anything is written
  // Every output goes into a fresh staging folder, moved over its folder only once the run is complete
  // (common/staged_directory.hpp); a bag inside --out travels with it.
  std::vector<std::unique_ptr<StagedDirectory>> staged;
  std::vector<RunOptions> options;
  for (std::size_t i = 0; i < twins.size(); ++i) {
    staged.push_back(std::make_unique<StagedDirectory>(twins[i].out_dir));
    options.push_back(run_options(o, scenarios[i], scenario_duration_s, *staged[i], i == 0));
  }
  std::vector<RunResult> results;
  try {
    results = run_all(scenarios, options);
    for (std::size_t i = 0; i < results.size(); ++i)
      if (!results[i].interrupted) write_report(results[i], staged[i]->path());
  } catch (const std::exception& e) {
    for (auto& s : staged) s->abandon(std::string("stvl-bench: error: ") + e.what());
    throw;
  }
  for (std::size_t i = 0; i < results.size(); ++i)
    if (results[i].interrupted) {
      for (std::size_t j = 1; j < staged.size(); ++j) staged[j]->abandon("interrupted");
      return abandon_interrupted_run(o, options[0], results[i], *staged[0]);
    }
  int exit_code = kExitOk;
  for (std::size_t i = 0; i < results.size(); ++i) {
    staged[i]->commit();
    print_run_summary(o, scenarios[i], results[i], staged[i]->final_path().string());
    if (!results[i].passed()) exit_code = kExitCheckFailed;
  }
  return exit_code;
}

const CommandRegistration kRun("run", [](CLI::App& app) {
  auto o = std::make_shared<RunCommandOptions>();
  auto* cmd = app.add_subcommand("run", "Run a scenario (the default office corridor when none is given)");
  cmd->add_option("scenario", o->scenario, "Scenario YAML file (default: scenarios/office_corridor.yaml)");
  cmd->add_option("--out", o->out_dir, "Output directory (default: out/<scenario name>)");
  cmd->add_option(
      "--bag", o->bag,
      "Also write the run as a ROS 1 bag (FILE.bag) or a rosbag2 folder with one MCAP file (FILE.mcap -> folder FILE)");
  add_bag_options(*cmd, o->bag_format, o->bag_compression, o->bag_topics);
  cmd->add_option("--set", o->sets,
                  "Set a scenario key before it is read, KEY=VALUE (dotted keys, list items as [i]; repeatable), e.g. "
                  "--set map.observation.clear_on_no_return=false")
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--seed", o->overrides.seed, "Override the scenario's seed (a non-negative integer)")
      ->check(CLI::Validator(seed_error, "UINT"));
  cmd->add_option("--filter", o->overrides.filter_type, "Override the filter: none | passthrough | voxel | csnb");
  cmd->add_option("--device", o->overrides.device, "Override the filter device: cpu | cuda | auto");
  cmd->add_option("--memory", o->overrides.memory, "Override the CUDA memory mode: copy | pinned | mapped | managed");
  cmd->add_option("--voxel-size", o->overrides.voxel_size_m, "Override the map and filter voxel size (m)");
  cmd->add_option("--duration", o->overrides.duration_s, "Override the duration (s)");
  cmd->add_option("--gl", o->overrides.gl_backend, "Override the GL backend: auto | egl | osmesa");
  cmd->add_option("--noise", o->noise, "Override the depth noise: on | off");
  cmd->add_flag(
      "--require-path", o->require_path,
      "Fail path_completed when --duration cuts the run short before the path's end (default: not evaluated)");
  cmd->add_flag("--no-run-ahead", o->no_run_ahead,
                "Make each frame after the last one's evaluation (default: the next frame is made meanwhile on a "
                "second thread; the outputs are the same)");
  cmd->add_option("--twin", o->twins,
                  "Also run the scenario with more --sets into another folder, on this run's drive (its physics, "
                  "renders and noise made once): OUT;KEY=VALUE;... with keys under map., filter., evaluation., "
                  "checks., outputs., name or a camera's edge_filter. (repeatable; each twin's outputs are those of "
                  "its own run; the bag is this run's only)")
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_flag("--no-progress", o->no_progress, "No progress output");
  cmd->add_flag("--profile", o->profile, "Print where the time went: per stage and per evaluation phase");
  return [o] { return run(*o); };
});

}  // namespace
}  // namespace stvl::tools
