#include "run/closed_loop.hpp"

#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>

#include "common/format.hpp"
#include "common/stopwatch.hpp"
#include "navigation/footprint.hpp"
#include "sim/contacts.hpp"

namespace stvl::run {
namespace {

navigation::Pose2 pose_of(const Eigen::Isometry3d& T) {
  const Eigen::Vector3d x_axis = T.linear().col(0);
  return {T.translation().x(), T.translation().y(), std::atan2(x_axis.y(), x_axis.x())};
}

std::string xy(const Eigen::Vector2d& p) {
  std::ostringstream o;
  o.setf(std::ios::fixed);
  o.precision(2);
  o << "(" << p.x() << ", " << p.y() << ")";
  return o.str();
}

// The free cell of `costmap` nearest to p (cost below inscribed), or p itself when there is none.
Eigen::Vector2d nearest_free(const mapping::Costmap2D& m, const Eigen::Vector2d& p) {
  double best = INFINITY;
  Eigen::Vector2d at = p;
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x) {
      if (m.cells[static_cast<std::size_t>(y) * m.width + x] >= navigation::kCostInscribed) continue;
      const Eigen::Vector2d c = m.origin_m + Eigen::Vector2d(x + 0.5, y + 0.5) * m.resolution_m;
      if ((c - p).squaredNorm() < best) best = (c - p).squaredNorm(), at = c;
    }
  return at;
}

}  // namespace

ClosedLoop::ClosedLoop(const config::Scenario& s, pipeline::Pipeline& pipeline, layer::Layer& layer,
                       const evaluation::RunEvaluation& evaluation, bool bag)
    : s_(s), pipeline_(pipeline), layer_(layer), evaluation_(evaluation), bag_(bag) {
  const navigation::NavigationConfig& c = s.navigation;
  const sim::World& world = pipeline.simulator().world();
  const evaluation::EvaluationConfig e = config::evaluation_config(s);
  Eigen::AlignedBox2d extent = world.extent_xy();
  const navigation::Pose2 start = robot_pose();
  extent.extend(Eigen::Vector2d(start.x_m, start.y_m));
  mapping::Costmap2D building = evaluation::building_map(world, c.static_bodies, c.global_costmap.resolution_m,
                                                         e.min_obstacle_height_m, e.max_obstacle_height_m, extent);
  // The goal against the truth now: inside the map, clear of every true obstacle by the inscribed radius, reachable.
  const Eigen::Vector2d goal(c.goal.x_m, c.goal.y_m);
  const std::string goal_text = "navigation.goal " + xy(goal) + " m";
  if (!Eigen::AlignedBox2d(building.origin_m,
                           building.origin_m + Eigen::Vector2d(building.width, building.height) * building.resolution_m)
           .contains(goal))
    throw std::invalid_argument(s.file + ": " + goal_text + " lies outside the map, x " +
                                fixed(building.origin_m.x(), 2) + " .. " +
                                fixed(building.origin_m.x() + building.width * building.resolution_m, 2) + " m, y " +
                                fixed(building.origin_m.y(), 2) + " .. " +
                                fixed(building.origin_m.y() + building.height * building.resolution_m, 2) + " m");
  drive_ = std::make_unique<evaluation::DriveEvaluation>(c, building, e.voxel_size_m,
                                                         s.pipeline.sim.drive == sim::DriveMode::kKinematic);
  // With moving bodies (people, carts) the truth now may block a way that opens later: the check then uses the
  // static map alone (the building), so that only a goal the building itself shuts off is refused.
  mapping::Costmap2D truth =
      evaluation.truth().has_moving_bodies() ? building : drive_->truth_inflated(evaluation.truth());
  if (evaluation.truth().has_moving_bodies())
    navigation::inflate(truth, c.inscribed_radius_m(), c.global_costmap.inflation);
  const std::string on = evaluation.truth().has_moving_bodies() ? "on the static map" : "on the true map";
  int gx, gy;
  navigation::world_to_cell(truth, goal.x(), goal.y(), gx, gy);
  if (truth.cells[static_cast<std::size_t>(gy) * truth.width + gx] >= navigation::kCostInscribed)
    throw std::invalid_argument(s.file + ": " + goal_text +
                                " is in or within the robot's inscribed radius of an obstacle (" + on +
                                "); the nearest free cell is " + xy(nearest_free(truth, goal)) + " m");
  navigation::NavfnParams strict = c.planner;
  strict.tolerance_m = 0;
  if (!navigation::navfn_plan(truth, {start.x_m, start.y_m}, goal, strict).found)
    throw std::invalid_argument(s.file + ": " + goal_text + " cannot be reached from the start " +
                                xy({start.x_m, start.y_m}) + " m even on the true map (NavFn finds no path)");
  if (c.static_map) {  // a nav2 map: the global costmap is the StaticLayer's grid of it, at its resolution
    navigation::NavigationConfig with_map = c;
    with_map.global_costmap.resolution_m = c.static_map->resolution_m;
    navigator_ = std::make_unique<navigation::Navigator>(
        with_map, navigation::static_layer_costmap(*c.static_map, c.global_costmap.track_unknown_space));
  } else {
    navigator_ = std::make_unique<navigation::Navigator>(c, std::move(building));
  }
  // nav2 runs one STVL instance per costmap, each reset by its own costmap's clearing; the bench's nav2 layers keep
  // one window (the local costmap's), which both costmaps read and both clearings reset.
  if (s.pipeline.layer_type == layer::LayerType::kStvl)
    global_layer_ = layer::make_layer(pipeline::layer_config(s.pipeline));
  layer::Layer& global_layer = global_layer_ ? *global_layer_ : layer_;
  navigator_->set_clear_layers([this](double t) { layer_.reset(t); },
                               [&global_layer](double t) { global_layer.reset(t); });
  navigator_->set_plan_observer([this](const navigation::PlanCycle& cycle, const navigation::NavCostmap& global) {
    const auto start = SteadyClock::now();
    drive_->plan_cycle(cycle, global, evaluation_.truth(), robot_pose());
    attribution_ms_ += ms_since(start);
  });
  pipeline.set_controller(
      [this](double time_s) {
        const sim::Simulator& sim = pipeline_.simulator();
        const Eigen::Vector2d rates = sim.robot().wheel_rates_radps();
        const double r = sim.robot().wheel_radius_m(), track = sim.robot().track_width_m();
        const navigation::Twist velocity{0.5 * r * (rates.x() + rates.y()), r * (rates.y() - rates.x()) / track};
        const auto start = SteadyClock::now();
        update_costmaps(time_s);  // nav2's costmaps run on their own timers, frames or not
        const navigation::Twist t = navigator_->tick(time_s, robot_pose(), velocity, localized_pose());
        navigation_ms_ += ms_since(start);
        if (bag_ && navigator_->status() == navigation::NavigationStatus::kRunning)
          twists_.emplace_back(time_s, Eigen::Vector2d(t.v_mps, t.omega_radps));
        return sim::Twist2D{t.v_mps, t.omega_radps};
      },
      1.0 / c.controller_frequency_hz);
}

navigation::Pose2 ClosedLoop::robot_pose() const { return pose_of(pipeline_.simulator().T_world_base()); }

std::optional<navigation::Pose2> ClosedLoop::localized_pose() const {
  if (!s_.pipeline.sim.localization.enabled) return std::nullopt;
  return pose_of(pipeline_.simulator().T_map_base());
}

void ClosedLoop::update_costmaps(double time_s) {
  const navigation::Pose2 robot = robot_pose();
  const bool local_due = navigator_->local_costmap().due(time_s);
  const bool global_due = navigator_->global_costmap().due(time_s);
  // The local costmap reads nav2's master around the layer when the scenario models it (map.nav2_costmap: its
  // bounds and ghosts), else the layer's own grid; the global one its own layer's grid (the run's layer where one
  // serves both). Each grid is projected once, and only when a costmap that reads it is due.
  std::optional<mapping::Costmap2D> own;
  const auto own_grid = [&]() -> const mapping::Costmap2D& {
    if (!own) own = layer_.costmap();
    return *own;
  };
  const layer::Layer& global_layer = global_layer_ ? *global_layer_ : layer_;
  if (global_due)
    navigator_->update_costmaps(time_s, global_layer_ ? global_layer_->costmap() : own_grid(),
                                localized_pose().value_or(robot), false, true, global_layer.current(time_s));
  if (local_due)
    navigator_->update_costmaps(time_s, layer_.master() ? layer_.master()->master() : own_grid(), robot, true, false,
                                layer_.current(time_s));
}

void ClosedLoop::after_frame(const pipeline::Frame& frame) {
  const double time_s = frame.time_s;
  const auto start = SteadyClock::now();
  if (global_layer_)
    global_layer_->update(frame.observation_map ? frame.observation_map : frame.observation, frame.cameras_now,
                          global_report_);
  navigation_ms_ += ms_since(start);
  judge(time_s);
}

void ClosedLoop::judge(double time_s) {
  const auto judged = SteadyClock::now();
  const sim::Simulator& sim = pipeline_.simulator();
  const sim::Twist2D& command = sim.commanded_twist();
  drive_->frame(time_s, robot_pose(), {command.v_mps, command.omega_radps}, evaluation_.truth(),
                sim::robot_contacts(sim.world(), sim.robot().base_body_id()),
                navigator_->status() == navigation::NavigationStatus::kRunning);
  attribution_ms_ += ms_since(judged);
}

void ClosedLoop::record_bag(BagRecorder& bag, double time_s) {
  BagRecorder::NavigationMessages m;
  m.twists.swap(twists_);
  const auto& plans = navigator_->plans();
  for (; plans_written_ < plans.size(); ++plans_written_) {
    const navigation::PlanCycle& p = plans[plans_written_];
    if (!p.found) continue;
    std::vector<Eigen::Vector3d> poses;
    for (std::size_t i = 0; i < p.path_W.size(); ++i)
      poses.emplace_back(p.path_W[i].x(), p.path_W[i].y(),
                         i + 1 == p.path_W.size() ? s_.navigation.goal.yaw_rad : 0.0);  // as NavFn orients them
    m.plans.emplace_back(p.time_s, std::move(poses));
  }
  const navigation::NavCostmap& local = navigator_->local_costmap();
  const navigation::NavCostmap& global = navigator_->global_costmap();
  constexpr double kEpsilon_s = 1e-9;
  if (time_s + kEpsilon_s >= next_local_publish_s_) {
    m.local.emplace_back(time_s, local.costmap());
    next_local_publish_s_ = time_s + 1.0 / local.params().publish_frequency_hz;
  }
  if (time_s + kEpsilon_s >= next_global_publish_s_) {
    m.global.emplace_back(time_s, global.costmap());
    next_global_publish_s_ = time_s + 1.0 / global.params().publish_frequency_hz;
  }
  bag.record_navigation(std::move(m));
}

evaluation::DriveSummary ClosedLoop::finish(double end_s) {
  evaluation::DriveSummary d = drive_->finish(*navigator_, end_s);
  d.navigation_ms = navigation_ms_;
  d.attribution_ms = attribution_ms_;
  // The drive ends with the navigation: a stall or a goal "reached" off the goal may be the localizer's doing.
  if (const std::optional<navigation::Pose2> localized = localized_pose()) {
    const navigation::Pose2 truth = robot_pose();
    const double off_m = std::hypot(localized->x_m - truth.x_m, localized->y_m - truth.y_m);
    const double off_deg = std::abs(std::remainder(localized->yaw_rad - truth.yaw_rad, 2.0 * M_PI)) * 180.0 / M_PI;
    char text[128];
    std::snprintf(text, sizeof text, "; the localizer was %.2f m and %.1f deg off the truth at the end", off_m,
                  off_deg);
    d.outcome += text;
  }
  return d;
}

}  // namespace stvl::run
