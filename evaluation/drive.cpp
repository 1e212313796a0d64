#include "evaluation/drive.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <sstream>

#include "navigation/footprint.hpp"
#include "truth/ground_truth.hpp"

namespace stvl::evaluation {
namespace {

constexpr double kStallSpeed_mps = 0.02;  // slower than this ...
constexpr double kStallMin_s = 1.0;       // ... for this long is a stall
constexpr double kLongerFactor = 1.5;     // a layer plan this much longer than the truth's is blocked

std::size_t index_of(const mapping::Costmap2D& m, int x, int y) { return static_cast<std::size_t>(y) * m.width + x; }

bool lethal_near(const mapping::Costmap2D& m, int x, int y, int tol) {
  for (int dy = -tol; dy <= tol; ++dy)
    for (int dx = -tol; dx <= tol; ++dx) {
      const int cx = x + dx, cy = y + dy;
      if (cx >= 0 && cy >= 0 && cx < m.width && cy < m.height && m.cells[index_of(m, cx, cy)] == mapping::kCostLethal)
        return true;
    }
  return false;
}

Eigen::Vector2d cell_centre(const mapping::Costmap2D& m, int x, int y) {
  return m.origin_m + Eigen::Vector2d(x + 0.5, y + 0.5) * m.resolution_m;
}

// Distance from p to the polygon's outline, negative inside.
double signed_distance_to_polygon(const Eigen::Vector2d& p, const std::vector<Eigen::Vector2d>& poly) {
  double best = std::numeric_limits<double>::infinity();
  bool inside = false;
  for (std::size_t i = 0, j = poly.size() - 1; i < poly.size(); j = i++) {
    const Eigen::Vector2d& a = poly[j];
    const Eigen::Vector2d& b = poly[i];
    const Eigen::Vector2d ab = b - a;
    const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-18), 0.0, 1.0);
    best = std::min(best, (a + t * ab - p).norm());
    if ((a.y() > p.y()) != (b.y() > p.y()) && p.x() < a.x() + (p.y() - a.y()) / (b.y() - a.y()) * ab.x())
      inside = !inside;
  }
  return inside ? -best : best;
}

// The shortest path from start to goal through cells the robot's centre may take (cost below inscribed): 8-connected
// Dijkstra on the cell centres, the two ends joined to their cells' centres. 0 when there is none.
double shortest_free_path_m(const mapping::Costmap2D& m, const Eigen::Vector2d& start, const Eigen::Vector2d& goal) {
  int sx, sy, gx, gy;
  if (!navigation::world_to_cell(m, start.x(), start.y(), sx, sy) ||
      !navigation::world_to_cell(m, goal.x(), goal.y(), gx, gy))
    return 0;
  std::vector<double> dist(m.cells.size(), std::numeric_limits<double>::infinity());
  using Item = std::pair<double, std::size_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  const std::size_t s0 = index_of(m, sx, sy), g0 = index_of(m, gx, gy);
  dist[s0] = 0;
  open.push({0, s0});
  while (!open.empty()) {
    const auto [d, i] = open.top();
    open.pop();
    if (d > dist[i]) continue;
    if (i == g0) break;
    const int x = static_cast<int>(i % m.width), y = static_cast<int>(i / m.width);
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const int nx = x + dx, ny = y + dy;
        if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= m.width || ny >= m.height) continue;
        const std::size_t j = index_of(m, nx, ny);
        if (j != g0 && m.cells[j] >= navigation::kCostInscribed) continue;
        const double nd = d + (dx != 0 && dy != 0 ? M_SQRT2 : 1.0) * m.resolution_m;
        if (nd < dist[j]) dist[j] = nd, open.push({nd, j});
      }
  }
  if (!std::isfinite(dist[g0])) return 0;
  return dist[g0] + (start - cell_centre(m, sx, sy)).norm() + (goal - cell_centre(m, gx, gy)).norm();
}

}  // namespace

mapping::Costmap2D building_map(const sim::World& world, const std::vector<std::string>& prefixes, double resolution_m,
                                double min_z_m, double max_z_m, const Eigen::AlignedBox2d& extent_W) {
  if (!(resolution_m > 0) || extent_W.isEmpty())
    throw std::invalid_argument("building map: resolution must be > 0 and the extent not empty");
  mapping::Costmap2D m;
  m.resolution_m = resolution_m;
  const Eigen::Vector2d lo = (extent_W.min() / resolution_m).array().floor() * resolution_m;
  const Eigen::Vector2d hi = (extent_W.max() / resolution_m).array().ceil() * resolution_m;
  m.origin_m = lo;
  m.width = static_cast<int>(std::lround((hi.x() - lo.x()) / resolution_m));
  m.height = static_cast<int>(std::lround((hi.y() - lo.y()) / resolution_m));
  if (static_cast<double>(m.width) * m.height > 4e7)
    throw std::invalid_argument("building map of " + std::to_string(m.width) + " x " + std::to_string(m.height) +
                                " cells is too large (4e7 at most): raise navigation.global_costmap.resolution");
  m.cells.assign(static_cast<std::size_t>(m.width) * m.height, mapping::kCostFree);
  std::vector<truth::ObstacleGeom> building;
  for (auto& g : truth::obstacle_geoms(world))
    for (const auto& prefix : prefixes)
      if (g.body_name.rfind(prefix, 0) == 0) {
        building.push_back(std::move(g));
        break;
      }
  for (const auto& body : truth::footprints(building, resolution_m, min_z_m, max_z_m))
    for (const CellKey& c : body.cells) {
      const int x = static_cast<int>(std::lround((c.x * resolution_m - lo.x()) / resolution_m));
      const int y = static_cast<int>(std::lround((c.y * resolution_m - lo.y()) / resolution_m));
      if (x >= 0 && y >= 0 && x < m.width && y < m.height) m.cells[index_of(m, x, y)] = mapping::kCostLethal;
    }
  return m;
}

std::vector<CheckResult> drive_checks(const ChecksConfig& c, const DriveSummary& d, bool cut_short,
                                      bool required_when_cut_short) {
  std::vector<CheckResult> out;
  const bool unjudged = cut_short && !d.success && !required_when_cut_short;
  const std::string why = "--duration cut the run short before the goal (" + d.outcome + ")";
  const auto text = [](double v) {
    std::ostringstream o;
    o.setf(std::ios::fixed);
    o.precision(2);
    o << v;
    return o.str();
  };
  if (c.navigation_success)
    out.push_back(unjudged ? not_evaluated("navigation_success", why)
                           : CheckResult{"navigation_success", d.success, d.outcome});
  if (c.collisions_max) {
    std::string m = std::to_string(d.collisions.size()) + " collisions (max " + std::to_string(*c.collisions_max) + ")";
    if (!d.collisions.empty())
      m += ": first with " + d.collisions.front().body + " at " + text(d.collisions.front().time_s) + " s";
    out.push_back({"collisions", static_cast<int>(d.collisions.size()) <= *c.collisions_max, m});
  }
  if (c.time_to_goal_max_s && unjudged) out.push_back(not_evaluated("time_to_goal", why));
  else if (c.time_to_goal_max_s)
    out.push_back({"time_to_goal", d.success && d.time_to_goal_s <= *c.time_to_goal_max_s,
                   d.success ? text(d.time_to_goal_s) + " s (max " + text(*c.time_to_goal_max_s) + " s)"
                             : "goal not reached (" + d.outcome + ")"});
  if (c.recoveries_max)
    out.push_back({"recoveries", static_cast<int>(d.recoveries) <= *c.recoveries_max,
                   std::to_string(d.recoveries) + " recoveries (max " + std::to_string(*c.recoveries_max) + ")"});
  if (c.blocked_time_max_s)
    out.push_back({"blocked_time", d.blocked_time_s <= *c.blocked_time_max_s,
                   text(d.blocked_time_s) + " s blocked by phantoms (" + std::to_string(d.blocked_cycles) + " of " +
                       std::to_string(d.attributions.size()) + " planning cycles; max " + text(*c.blocked_time_max_s) +
                       " s)"});
  return out;
}

DriveEvaluation::DriveEvaluation(const navigation::NavigationConfig& config, mapping::Costmap2D building,
                                 double truth_cell_m, bool geometric_collisions)
    : config_(config),
      building_(std::move(building)),
      footprint_m_(config.footprint_polygon_m()),
      truth_cell_m_(truth_cell_m),
      geometric_collisions_(geometric_collisions) {
  s_.evaluated = true;
  s_.min_clearance_m = std::numeric_limits<double>::infinity();
}

mapping::Costmap2D DriveEvaluation::truth_costmap(const Truth& truth) const {
  mapping::Costmap2D m = building_;
  const CellGrid& cells = truth.footprint();
  const double v = truth_cell_m_;
  cells.for_each([&](const CellKey& c, int) {
    int x, y;
    if (navigation::world_to_cell(m, (c.x + 0.5) * v, (c.y + 0.5) * v, x, y))
      m.cells[index_of(m, x, y)] = mapping::kCostLethal;
  });
  return m;
}

mapping::Costmap2D DriveEvaluation::truth_inflated(const Truth& truth) const {
  mapping::Costmap2D m = truth_costmap(truth);
  navigation::inflate(m, config_.inscribed_radius_m(), config_.global_costmap.inflation);
  return m;
}

void DriveEvaluation::frame(double time_s, const navigation::Pose2& robot, const navigation::Twist& command,
                            const Truth& truth, const std::vector<std::string>& contacts, bool navigating) {
  const Eigen::Vector2d p(robot.x_m, robot.y_m);
  double v = 0;
  if (last_time_s_ >= 0 && time_s > last_time_s_) {
    v = (p - last_p_).norm() / (time_s - last_time_s_);
    s_.path_length_m += (p - last_p_).norm();
  }
  s_.trajectory.push_back({time_s, robot.x_m, robot.y_m, robot.yaw_rad, v, command.omega_radps});
  // Stalls: slower than kStallSpeed for kStallMin while the navigation runs.
  const bool slow = navigating && last_time_s_ >= 0 && v < kStallSpeed_mps;
  if (slow && slow_since_s_ < 0) slow_since_s_ = last_time_s_;
  if ((!slow || !navigating) && slow_since_s_ >= 0) {
    if (last_time_s_ - slow_since_s_ >= kStallMin_s) {
      s_.stalls.push_back({slow_since_s_, last_time_s_, last_p_});
      s_.stalled_s += last_time_s_ - slow_since_s_;
    }
    slow_since_s_ = -1;
  }
  // Clearance: the placed footprint against every true footprint cell within reach.
  const std::vector<Eigen::Vector2d> placed = navigation::place_footprint(footprint_m_, p.x(), p.y(), robot.yaw_rad);
  double reach = 0;
  for (const auto& q : footprint_m_) reach = std::max(reach, q.norm());
  reach += 1.0;
  const double cell = truth_cell_m_;
  const CellGrid& cells = truth.footprint();
  double clearance = std::numeric_limits<double>::infinity();
  const int x0 = static_cast<int>(std::floor((p.x() - reach) / cell)),
            x1 = static_cast<int>(std::floor((p.x() + reach) / cell));
  const int y0 = static_cast<int>(std::floor((p.y() - reach) / cell)),
            y1 = static_cast<int>(std::floor((p.y() + reach) / cell));
  for (int y = y0; y <= y1; ++y)
    for (int x = x0; x <= x1; ++x)
      if (cells.contains({x, y}))
        clearance = std::min(clearance,
                             signed_distance_to_polygon(Eigen::Vector2d(x + 0.5, y + 0.5) * cell, placed) - 0.5 * cell);
  s_.min_clearance_m = std::min(s_.min_clearance_m, clearance);
  // Collisions: a body the robot starts touching (physics), or the footprint starting to overlap a true cell.
  for (const auto& body : contacts)
    if (std::find(touching_.begin(), touching_.end(), body) == touching_.end())
      s_.collisions.push_back({time_s, body, p});
  touching_ = contacts;
  const bool overlapping = geometric_collisions_ && clearance < 0;
  if (overlapping && !overlapping_) s_.collisions.push_back({time_s, "obstacle (footprint overlap)", p});
  overlapping_ = overlapping;
  last_time_s_ = time_s;
  last_p_ = p;
}

void DriveEvaluation::plan_cycle(const navigation::PlanCycle& cycle, const navigation::NavCostmap& global,
                                 const Truth& truth, const navigation::Pose2& robot_W) {
  PlanAttribution a;
  a.time_s = cycle.time_s;
  a.layer_found = cycle.found;
  a.layer_length_m = cycle.length_m;
  a.localization_error_m = std::hypot(cycle.robot_W.x_m - robot_W.x_m, cycle.robot_W.y_m - robot_W.y_m);
  const mapping::Costmap2D truth_combined = truth_costmap(truth);
  mapping::Costmap2D inflated = truth_combined;
  navigation::inflate(inflated, config_.inscribed_radius_m(), config_.global_costmap.inflation);
  const navigation::PlanResult t = navigation::navfn_plan(inflated, {robot_W.x_m, robot_W.y_m},
                                                          {config_.goal.x_m, config_.goal.y_m}, config_.planner);
  a.truth_found = t.found;
  a.truth_length_m = navigation::path_length_m(t.path_W);
  if (first_plan_s_ < 0) {  // SPL's shortest path: from where the drive started, on the truth then
    first_plan_s_ = cycle.time_s;
    const Eigen::Vector2d from(robot_W.x_m, robot_W.y_m), to(config_.goal.x_m, config_.goal.y_m);
    s_.shortest_truth_m = shortest_free_path_m(inflated, from, to);
    if (s_.shortest_truth_m == 0) {  // a moving body shuts the way now: the static map's shortest path then
      mapping::Costmap2D building = building_;
      navigation::inflate(building, config_.inscribed_radius_m(), config_.global_costmap.inflation);
      s_.shortest_truth_m = shortest_free_path_m(building, from, to);
    }
  }
  a.blocked_by_phantoms = a.truth_found && (!a.layer_found || a.layer_length_m >= kLongerFactor * a.truth_length_m);
  const mapping::Costmap2D& layer = global.combined();
  if (a.blocked_by_phantoms) {
    // The layer's lethal cells where the truth has none within a cell, near the truth's plan. The global costmap's
    // grid may be a nav2 map's (its own origin and resolution): cells meet the truth's by their centres.
    const double near_m = config_.global_costmap.inflation.inflation_radius_m;
    for (int y = 0; y < layer.height; ++y)
      for (int x = 0; x < layer.width; ++x) {
        if (layer.cells[index_of(layer, x, y)] != mapping::kCostLethal) continue;
        const Eigen::Vector2d c = cell_centre(layer, x, y);
        int tx, ty;
        if (!navigation::world_to_cell(truth_combined, c.x(), c.y(), tx, ty) || lethal_near(truth_combined, tx, ty, 1))
          continue;
        bool near = false;
        for (const auto& q : t.path_W)
          if ((q - c).squaredNorm() <= near_m * near_m) {
            near = true;
            break;
          }
        if (!near) continue;
        ++a.phantom_cells;
        if (a.phantom_cells_W.size() < kListed) a.phantom_cells_W.push_back(c);
      }
  }
  if (a.layer_found) {
    std::vector<std::size_t> seen;
    for (const auto& q : cycle.path_W) {
      int x, y;
      int lx, ly;
      if (!navigation::world_to_cell(truth_combined, q.x(), q.y(), x, y)) continue;
      const std::size_t i = index_of(truth_combined, x, y);
      const bool layer_lethal = navigation::world_to_cell(layer, q.x(), q.y(), lx, ly) &&
                                layer.cells[index_of(layer, lx, ly)] == mapping::kCostLethal;
      if (truth_combined.cells[i] != mapping::kCostLethal || layer_lethal) continue;
      if (std::find(seen.begin(), seen.end(), i) != seen.end()) continue;
      seen.push_back(i);
      ++a.unseen_cells;
      if (a.unseen_cells_W.size() < kListed) a.unseen_cells_W.push_back(cell_centre(truth_combined, x, y));
    }
    a.into_unseen = a.unseen_cells > 0;
  }
  s_.attributions.push_back(std::move(a));
}

DriveSummary DriveEvaluation::finish(const navigation::Navigator& navigator, double end_s) {
  if (slow_since_s_ >= 0 && last_time_s_ - slow_since_s_ >= kStallMin_s) {
    s_.stalls.push_back({slow_since_s_, last_time_s_, last_p_});
    s_.stalled_s += last_time_s_ - slow_since_s_;
  }
  s_.success = navigator.status() == navigation::NavigationStatus::kSucceeded;
  s_.time_to_goal_s = s_.success ? navigator.finished_at_s() : end_s;
  s_.spl = s_.success && s_.shortest_truth_m > 0 ? s_.shortest_truth_m / std::max(s_.path_length_m, s_.shortest_truth_m)
                                                 : 0.0;
  s_.events = navigator.events();
  s_.plan_log = navigator.plans();
  for (const auto& p : s_.plan_log) {
    ++s_.plans;
    if (!p.found) ++s_.plan_failures;
  }
  s_.recoveries = static_cast<std::size_t>(navigator.recoveries());
  for (std::size_t i = 0; i < s_.attributions.size(); ++i) {
    const PlanAttribution& a = s_.attributions[i];
    const double next = i + 1 < s_.attributions.size() ? s_.attributions[i + 1].time_s : end_s;
    if (a.blocked_by_phantoms) ++s_.blocked_cycles, s_.blocked_time_s += std::max(0.0, next - a.time_s);
    if (a.into_unseen) ++s_.unseen_cycles;
  }
  if (!std::isfinite(s_.min_clearance_m)) s_.min_clearance_m = -1;  // no obstacle within reach all along
  std::ostringstream o;
  o.setf(std::ios::fixed);
  o.precision(2);
  if (s_.success) {
    o << "goal reached at " << s_.time_to_goal_s << " s";
  } else {
    if (navigator.status() == navigation::NavigationStatus::kFailed) o << "navigation failed: " << navigator.failure();
    else o << "goal not reached by " << end_s << " s";
    if (!s_.collisions.empty())
      o << "; collided with " << s_.collisions.front().body << " at " << s_.collisions.front().time_s << " s";
    if (!s_.stalls.empty()) {
      const DriveStall& st = s_.stalls.back();
      o << "; stalled at (" << st.at_W.x() << ", " << st.at_W.y() << ") from " << st.from_s << " s";
      for (auto it = s_.attributions.rbegin(); it != s_.attributions.rend(); ++it)
        if (it->time_s <= st.to_s && it->blocked_by_phantoms) {
          o << ": " << it->phantom_cells << " lethal cells";
          if (!it->phantom_cells_W.empty())
            o << " at (" << it->phantom_cells_W.front().x() << ", " << it->phantom_cells_W.front().y() << ")";
          o << " where the truth is free";
          if (it->localization_error_m >= truth_cell_m_)  // the layer's cells misplaced by a cell and more
            o << ", the localizer " << it->localization_error_m << " m off then (the global costmap's readings "
              << "placed as far from where they were seen)";
          break;
        }
    }
  }
  s_.outcome = o.str();
  return s_;
}

}  // namespace stvl::evaluation
