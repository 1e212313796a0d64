// stvl-bench sweep SCENARIO|--worlds SPEC --set KEY=V1,V2 [--option NAME=V1,V2] [--seeds 1..5] [--jobs N | --emit
// ENGINE]: the grid of a scenario's variants, run here or written out for GNU parallel, CTest or Slurm; stvl-bench
// sweep --collect DIR: every point's metrics.json in one table (CSV, JSON, HTML with charts).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "analysis/sweep.hpp"
#include "analysis/sweep_page.hpp"
#include "common/atomic_file.hpp"
#include "common/staged_directory.hpp"
#include "config/scenario.hpp"
#include "run/runner.hpp"
#include "run/shared_drive.hpp"
#include "tools/command.hpp"

namespace stvl::tools {
using namespace stvl::config;
using namespace stvl::analysis;
namespace {

struct SweepOptions {
  std::string scenario;
  std::vector<std::string> sets, options;
  std::string seeds;
  std::string worlds;
  std::string out_dir;
  int jobs = 0;  // 0: one point per core (std::thread::hardware_concurrency)
  std::string emit;
  std::string collect;
  std::string junit;
  std::vector<std::string> twins;  // --twin OUT;KEY=VALUE;...
};

// --twin: each a sweep folder of its own, none of them the sweep's or another twin's.
std::vector<SweepTwin> sweep_twins(const SweepOptions& o, const std::string& out) {
  std::vector<SweepTwin> twins;
  std::vector<std::string> folders{out};
  for (const auto& text : o.twins) {
    const run::TwinSpec spec = run::parse_twin(text);
    for (const auto& other : folders)
      if (!folders_apart(spec.out_dir, other))
        throw std::invalid_argument("--twin '" + text + "': its folder " + spec.out_dir +
                                    " must lie apart from the sweep's folder and the other twins'");
    folders.push_back(spec.out_dir);
    twins.push_back({spec.out_dir, spec.sets});
  }
  return twins;
}

// --junit F: one testcase per point of the collected table.
void write_junit(const SweepOptions& o, const nlohmann::json& table) {
  if (o.junit.empty()) return;
  write_file_atomically(o.junit, sweep_junit(table));
  std::printf("sweep: JUnit in %s\n", o.junit.c_str());
}

// A point (with a twin's sets after its own) as its run loads it: a key that does not exist or a value of the wrong
// type names the assignment (and the point).
Scenario load_point(const std::string& sweep_scenario, const SweepPoint& p, const std::vector<std::string>& twin_sets) {
  std::vector<std::string> sets;
  ScenarioOverrides overrides;
  for (const auto& s : p.sets) {
    const std::size_t equals = s.find('=');
    const std::string key = s.substr(0, equals), value = s.substr(equals + 1);
    if (key.rfind("--", 0) != 0) {
      sets.push_back(s);
      continue;
    }
    const auto number = [&] {
      try {
        std::size_t used = 0;
        const double v = std::stod(value, &used);
        if (used == value.size()) return v;
      } catch (const std::exception&) {
      }
      throw std::invalid_argument("--option " + key.substr(2) + "=" + value + ": expected a number");
    };
    if (key == "--voxel-size") overrides.voxel_size_m = number();
    if (key == "--duration") overrides.duration_s = number();
    if (key == "--filter") overrides.filter_type = value;
    if (key == "--device") overrides.device = value;
    if (key == "--memory") overrides.memory = value;
    if (key == "--gl") overrides.gl_backend = value;
    if (key == "--noise") {
      if (value != "on" && value != "off")
        throw std::invalid_argument("--option noise=" + value + ": expected on or off");
      overrides.noise = value == "on";
    }
  }
  sets.insert(sets.end(), twin_sets.begin(), twin_sets.end());
  try {
    Scenario s = load_scenario(p.scenario.empty() ? sweep_scenario : p.scenario, sets);
    apply_overrides(s, overrides);
    return s;
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(std::string(e.what()) + " (sweep point " + p.name +
                                (twin_sets.empty() ? "" : ", its twin") + ")");
  }
}

// Every point and its twins must load before any runs.
void validate_points(const std::string& sweep_scenario, const std::vector<SweepPoint>& points,
                     const std::vector<SweepTwin>& twins) {
  std::size_t unshared = 0;
  for (const auto& p : points) {
    const Scenario s = load_point(sweep_scenario, p, {});
    for (const SweepTwin& twin : twins) load_point(sweep_scenario, p, twin.sets);
    unshared += !twins.empty() && !run::can_share_drive(s);
  }
  if (unshared > 0)
    std::printf("sweep: notice: %zu points drive in closed loop or with camera timing: their twins run after them\n",
                unshared);
}

int sweep(const SweepOptions& o) {
  if (!o.collect.empty()) {
    const auto table = collect_sweep(o.collect);
    std::printf("sweep: %zu points collected into %s/sweep.csv, sweep_table.json, sweep.html\n", table["rows"].size(),
                o.collect.c_str());
    write_junit(o, table);
    return kExitOk;
  }
  if (o.scenario.empty() && o.worlds.empty())
    throw std::invalid_argument("sweep: give a scenario file or --worlds (or --collect DIR)");
  if (!o.scenario.empty() && !o.worlds.empty())
    throw std::invalid_argument("sweep: give a scenario file or --worlds, not both (each world brings its scenario)");
  const std::string scenario = o.scenario.empty() ? "" : std::filesystem::absolute(o.scenario).string();
  std::vector<SweepAxis> axes;
  for (const auto& s : o.sets) axes.push_back(parse_sweep_axis(s));
  for (const auto& s : o.options) axes.push_back(parse_sweep_axis(s, true));
  const std::string out = !o.out_dir.empty() ? o.out_dir
                          : o.worlds.empty() ? "out/sweep-" + std::filesystem::path(scenario).stem().string()
                                             : "out/sweep-worlds";
  const std::string binary = std::filesystem::read_symlink("/proc/self/exe").string();
  std::vector<SweepWorld> worlds;
  if (!o.worlds.empty()) {
    worlds = prepare_worlds(binary, o.worlds, out);
    std::printf("sweep: %zu worlds in %s/worlds\n", worlds.size(), out.c_str());
  }
  const auto points =
      sweep_grid(axes, o.seeds.empty() ? std::vector<std::uint64_t>{} : parse_seeds(o.seeds), 10000, worlds);
  const std::vector<SweepTwin> twins = sweep_twins(o, out);
  validate_points(scenario, points, twins);
  if (!o.emit.empty()) {
    for (const auto& path : emit_sweep(o.emit, binary, scenario, out, points, twins))
      std::printf("sweep: wrote %s\n", path.c_str());
    std::printf("sweep: %zu points; then stvl-bench sweep --collect %s\n", points.size(), out.c_str());
    return kExitOk;
  }
  const int jobs = o.jobs > 0 ? o.jobs : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::printf("sweep: %zu points, %d at a time, into %s\n", points.size(), jobs, out.c_str());
  const int worst = run_sweep_locally(binary, scenario, out, points, jobs, twins);
  write_junit(o, collect_sweep(out));
  std::printf("sweep: table in %s/sweep.csv and %s/sweep.html\n", out.c_str(), out.c_str());
  for (const auto& twin : twins) {
    collect_sweep(twin.out_dir);
    std::printf("sweep: its twin's table in %s/sweep.csv and %s/sweep.html\n", twin.out_dir.c_str(),
                twin.out_dir.c_str());
  }
  return worst;
}

const CommandRegistration kSweep("sweep", [](CLI::App& app) {
  auto o = std::make_shared<SweepOptions>();
  auto* cmd = app.add_subcommand("sweep",
                                 "Run a scenario over a grid of settings and seeds, or write the grid for "
                                 "GNU parallel, CTest or Slurm; --collect merges the results");
  cmd->add_option("scenario", o->scenario, "Scenario YAML file");
  cmd->add_option("--set", o->sets, "An axis: a scenario key and its values, KEY=V1,V2,... (repeatable)")
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--option", o->options,
                  "An axis over a run option, NAME=V1,V2,... with NAME one of voxel-size (map and filter together), "
                  "filter, device, memory, duration, noise, gl (repeatable)")
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--seeds", o->seeds, "Seeds, e.g. 1..5 or 1,4,9 (the fastest-varying axis)");
  cmd->add_option("--worlds", o->worlds,
                  "A world axis instead of a scenario (the slowest-varying): generate:SEEDS (e.g. generate:1..200, "
                  "offices made by stvl-bench world generate) or a comma-separated list of nav2 map YAMLs (made into "
                  "worlds by world from-map) and scenario files; sweep.html gives each figure's mean, p5, p95 and "
                  "worst world with the command that reproduces it, and the share of worlds where each check holds");
  cmd->add_option("--out", o->out_dir, "Output folder: one subfolder per point (default: out/sweep-<scenario>)");
  cmd->add_option("--twin", o->twins,
                  "Also run every point with more --sets, on the point's drive (run --twin: physics, renders and "
                  "noise made once for both), into a sweep folder of its own: OUT;KEY=VALUE;... with keys under map., "
                  "filter., evaluation., checks., outputs., name or a camera's edge_filter. (repeatable); "
                  "--collect OUT gives its table")
      ->allow_extra_args(false)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--jobs", o->jobs, "Points run at once here (default: one per core)")->check(CLI::Range(1, 256));
  cmd->add_option("--emit", o->emit, "Write the grid for an engine instead of running it: parallel | ctest | slurm")
      ->check(CLI::IsMember({"parallel", "ctest", "slurm"}));
  cmd->add_option("--collect", o->collect, "Merge the points' metrics.json of a sweep folder into one table");
  cmd->add_option("--junit", o->junit,
                  "Also write JUnit XML, one testcase per point, to this file (with --jobs or --collect)");
  return [o] { return sweep(*o); };
});

}  // namespace
}  // namespace stvl::tools
