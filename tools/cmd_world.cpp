// stvl-bench world from-map MAP.yaml --out DIR | world generate --seed N --out DIR: a world (DIR/world.xml, with
// robot.xml beside it) and a ready scenario (DIR/scenario.yaml) from a nav2 map or from the office generator.
// Everything is built and checked in memory first (bad input: exit 2, nothing written), then written into a
// staging folder beside DIR that replaces DIR whole (common/staged_directory.hpp).
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>
#include <sstream>

#include "common/atomic_file.hpp"
#include "common/staged_directory.hpp"
#include "sim/world.hpp"
#include "tools/command.hpp"
#include "worldgen/map_world.hpp"
#include "worldgen/office_generator.hpp"

namespace stvl::tools {
namespace {

namespace fs = std::filesystem;

struct WorldOptions {
  std::string map_yaml, out_dir, name, start, goal, size = "20x12";
  double wall_height_m = 2.5;
  std::uint64_t seed = 1;
  int people = 3;
};

// "A,B" (or "AxB") as two finite numbers; `what` names the option in errors.
Eigen::Vector2d parse_pair(const std::string& text, char separator, const std::string& what) {
  std::istringstream in(text);
  double a = 0, b = 0;
  char sep = 0;
  if (!(in >> a >> sep >> b) || sep != separator || !(in >> std::ws).eof() || !std::isfinite(a) || !std::isfinite(b))
    throw std::invalid_argument(what + " '" + text + "': expected two numbers as X" + std::string(1, separator) + "Y");
  return {a, b};
}

// Writes the world, robot.xml and the scenario into a staging folder, checks that MuJoCo loads the world there,
// and moves the folder into place.
void write_world_dir(const std::string& out_dir, const std::string& world_xml, const std::string& scenario_yaml) {
  StagedDirectory staged(out_dir);
  std::ifstream robot(worldgen::shipped_robot_xml(), std::ios::binary);
  if (!robot) throw std::runtime_error("cannot read " + worldgen::shipped_robot_xml());
  write_file_atomically(staged.path() / "robot.xml", std::string(std::istreambuf_iterator<char>(robot), {}));
  write_file_atomically(staged.path() / "world.xml", world_xml);
  sim::World::from_file((staged.path() / "world.xml").string());  // MuJoCo's own check, before the folder counts
  write_file_atomically(staged.path() / "scenario.yaml", scenario_yaml);
  staged.commit();
}

int from_map(const WorldOptions& o) {
  const worldgen::MapWorld world = worldgen::build_map_world(o.map_yaml, o.wall_height_m);
  const double radius_m = worldgen::robot_footprint_radius_m(worldgen::shipped_robot_xml());
  std::optional<Eigen::Vector2d> start, goal;
  if (!o.start.empty()) start = parse_pair(o.start, ',', "--start");
  if (!o.goal.empty()) goal = parse_pair(o.goal, ',', "--goal");
  worldgen::PlannedPath path;
  try {
    path = worldgen::plan_path(worldgen::map_drive_grid(world, radius_m), world.grid.cells, start, goal, "--start",
                               "--goal");
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(o.map_yaml + ": " + e.what());
  }
  const std::string name = o.name.empty() ? fs::path(o.map_yaml).stem().string() : o.name;
  write_world_dir(o.out_dir, worldgen::write_mjcf(world.spec),
                  worldgen::map_scenario_yaml(world, path, name, "world.xml"));
  std::printf("%s: %d x %d cells, %zu wall boxes; path %.1f m, %zu waypoints (robot radius %.3f m + %.2f m)\n",
              o.map_yaml.c_str(), world.grid.frame.width, world.grid.frame.height, world.wall_boxes, path.length_m,
              path.waypoints_W.size(), radius_m, worldgen::kPathMarginM);
  std::printf("wrote %s/world.xml, robot.xml, scenario.yaml; run: stvl-bench run %s/scenario.yaml\n", o.out_dir.c_str(),
              o.out_dir.c_str());
  return kExitOk;
}

int generate(const WorldOptions& o) {
  worldgen::OfficeOptions options;
  options.seed = o.seed;
  const Eigen::Vector2d size = parse_pair(o.size, 'x', "--size");
  options.width_m = size.x(), options.height_m = size.y();
  options.people = o.people;
  options.wall_height_m = o.wall_height_m;
  const worldgen::OfficeWorld world =
      worldgen::generate_office(options, worldgen::robot_footprint_radius_m(worldgen::shipped_robot_xml()));
  const std::string name = o.name.empty() ? "office_seed_" + std::to_string(o.seed) : o.name;
  write_world_dir(o.out_dir, worldgen::write_mjcf(world.spec),
                  worldgen::office_scenario_yaml(world, options, name, "world.xml"));
  std::printf("office seed %llu: %s\n", static_cast<unsigned long long>(o.seed), world.summary.c_str());
  std::printf("wrote %s/world.xml, robot.xml, scenario.yaml; run: stvl-bench run %s/scenario.yaml\n", o.out_dir.c_str(),
              o.out_dir.c_str());
  return kExitOk;
}

const CommandRegistration kWorld("world", [](CLI::App& app) {
  auto o = std::make_shared<WorldOptions>();
  auto* cmd = app.add_subcommand("world", "Build a world and a ready scenario: from a nav2 map, or a generated office");
  cmd->require_subcommand(1);
  auto* map = cmd->add_subcommand(
      "from-map", "Walls from a nav2 / map_server map's occupied cells, a path planned through its free cells");
  map->add_option("map", o->map_yaml,
                  "map_server YAML (image, resolution, origin, negate, occupied_thresh, free_thresh, mode)")
      ->required();
  map->add_option("--out", o->out_dir, "Folder to write world.xml, robot.xml and scenario.yaml into (replaced whole)")
      ->required();
  map->add_option("--wall-height-m", o->wall_height_m, "Height of the walls (m)")->capture_default_str();
  map->add_option("--start", o->start,
                  "X,Y: where the path starts (m, world frame; default: one end of the map's longest path)");
  map->add_option("--goal", o->goal, "X,Y: where the path ends (default: the farthest reachable point)");
  map->add_option("--name", o->name, "The scenario's name (default: the map's file name)");
  auto* gen = cmd->add_subcommand(
      "generate", "A generated office: corridors, rooms, doors, furniture, people; the same seed gives the same files");
  gen->add_option("--seed", o->seed, "Seed of the generator")->capture_default_str();
  gen->add_option("--size", o->size, "WxH: the building (m), 12..60 by 8..40")->capture_default_str();
  gen->add_option("--people", o->people, "People standing and walking, 0..20")->capture_default_str();
  gen->add_option("--wall-height-m", o->wall_height_m, "Height of the walls (m), 2.2..5")->capture_default_str();
  gen->add_option("--out", o->out_dir, "Folder to write world.xml, robot.xml and scenario.yaml into (replaced whole)")
      ->required();
  gen->add_option("--name", o->name, "The scenario's name (default: office_seed_N)");
  return [o, map] { return map->parsed() ? from_map(*o) : generate(*o); };
});

}  // namespace
}  // namespace stvl::tools
