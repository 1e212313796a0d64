// stvl-bench lint PARAMS.yaml [--layer NAME] [--costmap NAME]: what STVL (or nav2's VoxelLayer / ObstacleLayer) does
// with a layer's ROS parameters that users rarely mean. Exit 0 without findings, 1 with findings, 2 for a file that
// cannot be read.
#include <cstdio>
#include <memory>

#include "config/ros_lint.hpp"
#include "config/ros_nav2_layer.hpp"
#include "config/ros_navigation.hpp"
#include "config/ros_params_detail.hpp"
#include "tools/command.hpp"

namespace stvl::tools {
using namespace stvl::config;
namespace {

struct LintOptions {
  std::string params;
  std::string layer;
  std::string costmap;
};

const char* flavour_name(RosFlavour flavour) {
  switch (flavour) {
    case RosFlavour::kRos2: return "ROS 2 (nav2)";
    case RosFlavour::kRos1: return "ROS 1 (move_base)";
    case RosFlavour::kBare: return "bare layer, read by ROS 2's rules";
  }
  return "?";
}

int lint_layer(const LintOptions& o);

// nav2's VoxelLayer or ObstacleLayer: its own findings (config/ros_nav2_layer.hpp).
int lint_nav2(const LintOptions& o) {
  const auto findings = lint_ros_nav2_layer(o.params, o.layer, o.costmap);
  const RosNav2Layer layer = load_ros_nav2_layer(o.params, o.layer, o.costmap);
  for (const auto& f : findings) std::printf("%s\n", format_finding(f).c_str());
  std::printf("%s: %zu finding%s on %s in %s (%s, ROS 2 (nav2))\n", o.params.c_str(), findings.size(),
              findings.size() == 1 ? "" : "s", layer.layer_name.c_str(), layer.costmap_name.c_str(),
              layer.plugin.c_str());
  return findings.empty() ? kExitOk : kExitCheckFailed;
}

// The closed loop's servers (controller_server, planner_server, ...): plugins not modelled and what stands in. A file
// without nav2's servers has none.
std::size_t lint_navigation(const LintOptions& o) {
  navigation::NavigationConfig c;
  std::vector<LintFinding> findings;
  try {
    findings = read_ros_navigation(o.params, c);
  } catch (const std::invalid_argument& e) {
    if (std::string(e.what()).find("no nav2 server") != std::string::npos) return 0;
    throw;
  }
  for (const auto& f : findings) std::printf("%s\n", format_finding(f).c_str());
  return findings.size();
}

int lint(const LintOptions& o) {
  const std::size_t navigation_findings = lint_navigation(o);
  const int layer = lint_layer(o);
  return navigation_findings > 0 && layer == kExitOk ? kExitCheckFailed : layer;
}

int lint_layer(const LintOptions& o) {
  if (ros_layer_is_nav2(o.params, o.layer, o.costmap)) return lint_nav2(o);
  const auto findings = lint_ros_stvl_layer(o.params, o.layer, o.costmap);
  const RosStvlLayer layer = ros_detail::read_layer(o.params, o.layer, o.costmap, true).layer;
  for (const auto& f : findings) std::printf("%s\n", format_finding(f).c_str());
  const std::string name = layer.layer_name.empty() ? "the layer" : layer.layer_name;
  std::printf("%s: %zu finding%s on %s%s%s (%s)\n", o.params.c_str(), findings.size(), findings.size() == 1 ? "" : "s",
              name.c_str(), layer.costmap_name.empty() ? "" : " in ", layer.costmap_name.c_str(),
              flavour_name(layer.flavour));
  return findings.empty() ? kExitOk : kExitCheckFailed;
}

const CommandRegistration kLint("lint", [](CLI::App& app) {
  auto o = std::make_shared<LintOptions>();
  auto* cmd = app.add_subcommand("lint",
                                 "Report what STVL or nav2's voxel / obstacle layer does with its ROS parameters that "
                                 "users rarely mean");
  cmd->add_option("params", o->params, "ROS parameter file (nav2 params, move_base costmap, or a bare layer)")
      ->required();
  cmd->add_option("--layer", o->layer, "Layer name (default: the only STVL, VoxelLayer or ObstacleLayer layer)");
  cmd->add_option("--costmap", o->costmap, "Costmap name, e.g. local_costmap (default: the only one with the layer)");
  return [o] { return lint(*o); };
});

}  // namespace
}  // namespace stvl::tools
