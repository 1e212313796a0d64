// nav2's NavFn planner, rewritten from ros-navigation/navigation2 jazzy f4108e5 (nav2_navfn_planner/src/navfn.cpp,
// src/navfn_planner.cpp, include/nav2_navfn_planner/navfn.hpp). The arithmetic keeps nav2's types: potentials and
// gradients are float, the quadratic update's polynomial and INVSQRT2 are double literals rounded to float, calcPath's
// grid fallback compares against an int minimum, hypot of ints is double and of floats is float.
//
// Checked against nav2's own navfn.cpp, compiled with stubs outside this repository: bit-identical potentials and
// calcPath points on 400 random inflated grids (Dijkstra and A*, allow_unknown both ways) and a 3000 x 3000 grid.
//
// Left out: the planner's cancel checker (nothing cancels here) and the debug statistics; clearRobotCell writes
// into a copy of the costmap rather than the shared master costmap (nav2's write persists until the costmap's next
// update overwrites that cell).
#include "navigation/navfn.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace stvl::navigation {
namespace {

constexpr int kPriorityBufSize = 10000;        // PRIORITYBUFSIZE
constexpr std::uint8_t kCostObsRos = 253;      // COST_OBS_ROS
constexpr std::uint8_t kCostUnknownRos = 255;  // COST_UNKNOWN_ROS
constexpr double kCostFactor = 0.8;            // COST_FACTOR
constexpr double kInvSqrt2 = 0.707106781;      // INVSQRT2
constexpr double kPotHighD = 1.0e10;           // POT_HIGH as the double nav2's comparisons promote to
enum Buffer { kCur = 0, kNext = 1, kOver = 2 };

// float -> int as x86-64's cvttss2si does it: truncation, INT_MIN out of range. nav2's calcPath converts POT_HIGH
// (1e10) to its int minimum that way (undefined behaviour in C++, INT_MIN on the machines nav2 runs on).
int float_to_int_x86(float f) {
  if (f >= -2147483648.0f && f < 2147483648.0f) return static_cast<int>(f);
  return INT_MIN;
}

int checked_side(int cells) {
  if (cells < 1) throw std::invalid_argument("NavFn: grid must be at least 1 x 1");
  return cells;
}

}  // namespace

std::uint8_t navfn_cost(std::uint8_t costmap_cost, bool allow_unknown) {
  // NavFn::setCostmap with isROS: 0..252 spread over 50..251; 253 (inscribed) and 254 (lethal) are obstacles.
  if (costmap_cost < kCostObsRos) {
    int v = static_cast<int>(kNavfnCostNeutral + kCostFactor * costmap_cost);
    if (v >= kNavfnCostObs) v = kNavfnCostObs - 1;
    return static_cast<std::uint8_t>(v);
  }
  if (costmap_cost == kCostUnknownRos && allow_unknown) return kNavfnCostObs - 1;
  return kNavfnCostObs;
}

NavFn::NavFn(int nx, int ny)
    : nx_(checked_side(nx)),
      ny_(checked_side(ny)),
      ns_(nx * ny),
      pad_(2 * nx + 2),
      cost_(static_cast<std::size_t>(ns_), 0),
      pot_store_(static_cast<std::size_t>(ns_ + 2 * pad_), kNavfnPotHigh),
      gradx_store_(pot_store_.size(), 0.0f),
      grady_store_(pot_store_.size(), 0.0f),
      pot_(pot_store_.data() + pad_),
      gradx_(gradx_store_.data() + pad_),
      grady_(grady_store_.data() + pad_),
      pending_(static_cast<std::size_t>(ns_), 0),
      pri_inc_(2 * kNavfnCostNeutral) {
  for (auto& b : buf_) b.assign(kPriorityBufSize, 0);
  cur_p_ = buf_[0].data();
  next_p_ = buf_[1].data();
  over_p_ = buf_[2].data();
}

void NavFn::set_costmap(const std::uint8_t* cells, bool allow_unknown) {
  for (int i = 0; i < ns_; ++i) cost_[i] = navfn_cost(cells[i], allow_unknown);
}

// push_cur / push_next / push_over.
void NavFn::push(int which, int n) {
  if (n < 0 || n >= ns_ || pending_[n] || cost_[n] >= kNavfnCostObs) return;
  int*& buf = which == kCur ? cur_p_ : which == kNext ? next_p_ : over_p_;
  int& end = which == kCur ? cur_pe_ : which == kNext ? next_pe_ : over_pe_;
  if (end >= kPriorityBufSize) return;  // a full buffer drops the cell, as nav2's macros do
  buf[end++] = n;
  pending_[n] = 1;
}

// setupNavFn(true): potentials high, gradients zero, the border made obstacle, buffers empty, the goal seeded.
void NavFn::setup() {
  std::fill(pot_store_.begin(), pot_store_.end(), kNavfnPotHigh);
  std::fill(gradx_store_.begin(), gradx_store_.end(), 0.0f);
  std::fill(grady_store_.begin(), grady_store_.end(), 0.0f);
  for (int i = 0; i < nx_; ++i) cost_[i] = cost_[(ny_ - 1) * nx_ + i] = kNavfnCostObs;
  for (int j = 0; j < ny_; ++j) cost_[j * nx_] = cost_[j * nx_ + nx_ - 1] = kNavfnCostObs;
  cur_t_ = kNavfnCostObs;
  cur_p_ = buf_[0].data();
  next_p_ = buf_[1].data();
  over_p_ = buf_[2].data();
  cur_pe_ = next_pe_ = over_pe_ = 0;
  std::fill(pending_.begin(), pending_.end(), 0);
  init_cost(goal_[0] + goal_[1] * nx_, 0.0f);
}

void NavFn::init_cost(int k, float v) {
  pot_[k] = v;
  push(kCur, k + 1);
  push(kCur, k - 1);
  push(kCur, k - nx_);
  push(kCur, k + nx_);
}

// updateCell / updateCellAstar: the planar-wave update from the lowest neighbour in x and in y. Only called for
// cells below COST_OBS, which are never on the border, so the four neighbours exist.
template <bool kAstar>
void NavFn::update_cell(int n) {
  const float l = pot_[n - 1];
  const float r = pot_[n + 1];
  const float u = pot_[n - nx_];
  const float d = pot_[n + nx_];
  float ta, tc;
  if (l < r) tc = l;
  else tc = r;
  if (u < d) ta = u;
  else ta = d;
  if (cost_[n] >= kNavfnCostObs) return;
  const float hf = static_cast<float>(cost_[n]);
  float dc = tc - ta;
  if (dc < 0) {
    dc = -dc;
    ta = tc;
  }
  float pot;
  if (dc >= hf) {
    pot = ta + hf;  // one neighbour only
  } else {
    const float div = dc / hf;  // quadratic approximation of the two-neighbour interpolation
    const float v = -0.2301 * div * div + 0.5307 * div + 0.7040;
    pot = ta + hf * v;
  }
  if (!(pot < pot_[n])) return;
  const float le = kInvSqrt2 * static_cast<float>(cost_[n - 1]);
  const float re = kInvSqrt2 * static_cast<float>(cost_[n + 1]);
  const float ue = kInvSqrt2 * static_cast<float>(cost_[n - nx_]);
  const float de = kInvSqrt2 * static_cast<float>(cost_[n + nx_]);
  pot_[n] = pot;
  if (kAstar) {
    // The Euclidean heuristic to the start cell, in neutral-cost units, decides the buffer (not stored).
    const int x = n % nx_;
    const int y = n / nx_;
    const float dist = std::hypot(x - start_[0], y - start_[1]) * static_cast<float>(kNavfnCostNeutral);
    pot += dist;
  }
  const int target = pot < cur_t_ ? kNext : kOver;
  if (l > pot + le) push(target, n - 1);
  if (r > pot + re) push(target, n + 1);
  if (u > pot + ue) push(target, n - nx_);
  if (d > pot + de) push(target, n + nx_);
}

// propNavFnDijkstra / propNavFnAstar: process the current buffer; cells below the threshold curT go to the next
// buffer, the rest to the overflow buffer; when the current level is exhausted, curT rises by priInc and the
// overflow becomes current. Stops when the buffers are empty, after `cycles`, or at the start cell (A* always).
template <bool kAstar>
bool NavFn::propagate(int cycles, bool at_start) {
  if (kAstar) {
    const float dist = std::hypot(goal_[0] - start_[0], goal_[1] - start_[1]) * static_cast<float>(kNavfnCostNeutral);
    cur_t_ = dist + cur_t_;
  }
  const int start_cell = start_[1] * nx_ + start_[0];
  int cycle = 0;
  for (; cycle < cycles; ++cycle) {
    if (cur_pe_ == 0 && next_pe_ == 0) break;
    for (int i = 0; i < cur_pe_; ++i) pending_[cur_p_[i]] = 0;
    for (int i = 0; i < cur_pe_; ++i) update_cell<kAstar>(cur_p_[i]);
    cur_pe_ = next_pe_;
    next_pe_ = 0;
    std::swap(cur_p_, next_p_);
    if (cur_pe_ == 0) {
      cur_t_ += pri_inc_;
      cur_pe_ = over_pe_;
      over_pe_ = 0;
      std::swap(cur_p_, over_p_);
    }
    if ((kAstar || at_start) && pot_[start_cell] < kPotHighD) break;
  }
  cycles_ = cycle;
  if (kAstar) {
    last_path_cost_ = pot_[start_cell];
    return pot_[start_cell] < kPotHighD;
  }
  return cycle < cycles;
}

bool NavFn::calc_dijkstra(bool at_start) {
  setup();
  return propagate<false>(std::max(nx_ * ny_ / 20, nx_ + ny_), at_start);
}

bool NavFn::calc_astar() {
  setup();
  return propagate<true>(std::max(nx_ * ny_ / 20, nx_ + ny_), true);
}

// gradCell: the normalised gradient at a cell, cached when gradx + grady > 0 (nav2's test, kept as is).
float NavFn::grad_cell(int n) {
  if (gradx_[n] + grady_[n] > 0.0) return 1.0f;
  if (n < nx_ || n > ns_ - nx_) return 0.0f;
  const float cv = pot_[n];
  float dx = 0.0f;
  float dy = 0.0f;
  if (cv >= kPotHighD) {  // in an obstacle: point out towards a reached neighbour
    if (pot_[n - 1] < kPotHighD) dx = -kNavfnCostObs;
    else if (pot_[n + 1] < kPotHighD) dx = kNavfnCostObs;
    if (pot_[n - nx_] < kPotHighD) dy = -kNavfnCostObs;
    else if (pot_[n + nx_] < kPotHighD) dy = kNavfnCostObs;
  } else {
    if (pot_[n - 1] < kPotHighD) dx += pot_[n - 1] - cv;
    if (pot_[n + 1] < kPotHighD) dx += cv - pot_[n + 1];
    if (pot_[n - nx_] < kPotHighD) dy += pot_[n - nx_] - cv;
    if (pot_[n + nx_] < kPotHighD) dy += cv - pot_[n + nx_];
  }
  float norm = std::hypot(dx, dy);
  if (norm > 0) {
    norm = 1.0 / norm;
    gradx_[n] = norm * dx;
    grady_[n] = norm * dy;
  }
  return norm;
}

// calcPath: from the start cell, half-cell steps down the bilinearly interpolated gradient; on a cell next to an
// unreached one, or when the last point repeats the one before the previous (oscillation), step to the lowest of the
// eight neighbours instead. Done when the nearest cell's potential is below COST_NEUTRAL: the goal cell is appended.
int NavFn::calc_path(int max_cycles) {
  path_x_.clear();
  path_y_.clear();
  int stc = start_[1] * nx_ + start_[0];
  float dx = 0;
  float dy = 0;
  for (int i = 0; i < max_cycles; ++i) {
    const int nearest_point = std::max(
        0, std::min(nx_ * ny_ - 1, stc + static_cast<int>(std::round(dx)) + static_cast<int>(nx_ * std::round(dy))));
    if (pot_[nearest_point] < kNavfnCostNeutral) {
      path_x_.push_back(static_cast<float>(goal_[0]));
      path_y_.push_back(static_cast<float>(goal_[1]));
      return static_cast<int>(path_x_.size());
    }
    if (stc < nx_ || stc > ns_ - nx_) return 0;  // out of bounds
    path_x_.push_back(stc % nx_ + dx);
    path_y_.push_back(stc / nx_ + dy);
    const std::size_t npath = path_x_.size();
    const bool oscillation =
        npath > 2 && path_x_[npath - 1] == path_x_[npath - 3] && path_y_[npath - 1] == path_y_[npath - 3];
    const int stcnx = stc + nx_;
    const int stcpx = stc - nx_;
    if (pot_[stc] >= kPotHighD || pot_[stc + 1] >= kPotHighD || pot_[stc - 1] >= kPotHighD ||
        pot_[stcnx] >= kPotHighD || pot_[stcnx + 1] >= kPotHighD || pot_[stcnx - 1] >= kPotHighD ||
        pot_[stcpx] >= kPotHighD || pot_[stcpx + 1] >= kPotHighD || pot_[stcpx - 1] >= kPotHighD || oscillation) {
      // Follow the grid: the first of the eight neighbours (row below, own row, row above) under the running int
      // minimum (nav2 keeps it in an int, truncating each potential).
      int minc = stc;
      int minp = float_to_int_x86(pot_[stc]);
      for (const int sti : {stcpx - 1, stcpx, stcpx + 1, stc - 1, stc + 1, stcnx - 1, stcnx, stcnx + 1}) {
        if (pot_[sti] < static_cast<float>(minp)) {
          minp = float_to_int_x86(pot_[sti]);
          minc = sti;
        }
      }
      stc = minc;
      dx = 0;
      dy = 0;
      if (pot_[stc] >= kPotHighD) return 0;  // no path: high potential
    } else {
      grad_cell(stc);
      grad_cell(stc + 1);
      grad_cell(stcnx);
      grad_cell(stcnx + 1);
      const float x1 = (1.0 - dx) * gradx_[stc] + dx * gradx_[stc + 1];
      const float x2 = (1.0 - dx) * gradx_[stcnx] + dx * gradx_[stcnx + 1];
      const float x = (1.0 - dy) * x1 + dy * x2;
      const float y1 = (1.0 - dx) * grady_[stc] + dx * grady_[stc + 1];
      const float y2 = (1.0 - dx) * grady_[stcnx] + dx * grady_[stcnx + 1];
      const float y = (1.0 - dy) * y1 + dy * y2;
      if (x == 0.0 && y == 0.0) return 0;  // zero gradient
      const float ss = path_step_ / std::hypot(x, y);
      dx += x * ss;
      dy += y * ss;
      if (dx > 1.0) {
        stc++;
        dx -= 1.0;
      }
      if (dx < -1.0) {
        stc--;
        dx += 1.0;
      }
      if (dy > 1.0) {
        stc += nx_;
        dy -= 1.0;
      }
      if (dy < -1.0) {
        stc -= nx_;
        dy += 1.0;
      }
    }
  }
  return 0;  // out of cycles: path too long
}

// ---- NavfnPlanner (navfn_planner.cpp) ----

namespace {

struct Grid {
  int nx, ny;
  double resolution_m;
  double origin_x_m, origin_y_m;
};

// Costmap2D::worldToMap (nav2_costmap_2d/src/costmap_2d.cpp): floor, used by createPlan's checks.
bool costmap_world_to_map(const Grid& g, double wx, double wy, int& mx, int& my) {
  if (!std::isfinite(wx) || !std::isfinite(wy)) return false;
  if (wx < g.origin_x_m || wy < g.origin_y_m) return false;
  const double fx = (wx - g.origin_x_m) / g.resolution_m;
  const double fy = (wy - g.origin_y_m) / g.resolution_m;
  if (fx >= g.nx || fy >= g.ny) return false;
  mx = static_cast<int>(fx);
  my = static_cast<int>(fy);
  return true;
}

// NavfnPlanner::worldToMap: round to the nearest cell index; `mx`, `my` are set even when out of bounds (only
// called for points Costmap2D::worldToMap accepted or after checking wx, wy >= origin).
bool planner_world_to_map(const Grid& g, double wx, double wy, int& mx, int& my) {
  if (!std::isfinite(wx) || !std::isfinite(wy)) return false;
  if (wx < g.origin_x_m || wy < g.origin_y_m) return false;
  const double rx = std::round((wx - g.origin_x_m) / g.resolution_m);
  const double ry = std::round((wy - g.origin_y_m) / g.resolution_m);
  if (rx > INT_MAX / 2 || ry > INT_MAX / 2) return false;
  mx = static_cast<int>(rx);
  my = static_cast<int>(ry);
  return mx < g.nx && my < g.ny;
}

double squared_distance(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const double dx = a.x() - b.x();
  const double dy = a.y() - b.y();
  return dx * dx + dy * dy;
}

std::string coordinates(const Eigen::Vector2d& p) {
  return "(" + std::to_string(p.x()) + ", " + std::to_string(p.y()) + ")";
}

PlanResult failed(PlanResult r, PlanFailure kind, std::string why) {
  r.found = false;
  r.path_W.clear();
  r.failure_kind = kind;
  r.failure = std::move(why);
  return r;
}

}  // namespace

void NavfnParams::validate() const {
  if (!(tolerance_m >= 0.0) || !std::isfinite(tolerance_m))
    throw std::invalid_argument("navfn: tolerance must be finite and >= 0, got " + std::to_string(tolerance_m));
}

PlanResult navfn_plan(const mapping::Costmap2D& costmap, const Eigen::Vector2d& start_W, const Eigen::Vector2d& goal_W,
                      const NavfnParams& p) {
  p.validate();
  if (costmap.width < 1 || costmap.height < 1 ||
      costmap.cells.size() != static_cast<std::size_t>(costmap.width) * static_cast<std::size_t>(costmap.height))
    throw std::invalid_argument("navfn: costmap cells do not match width x height");
  if (!(costmap.resolution_m > 0.0) || !std::isfinite(costmap.resolution_m))
    throw std::invalid_argument("navfn: costmap resolution_m must be > 0");
  const Grid g{costmap.width, costmap.height, costmap.resolution_m, costmap.origin_m.x(), costmap.origin_m.y()};
  const int ns = g.nx * g.ny;
  PlanResult result;
  result.goal_used_W = goal_W;
  result.goal_potential = kNavfnPotHigh;

  // createPlan's checks.
  int mx = 0, my = 0;
  if (!costmap_world_to_map(g, start_W.x(), start_W.y(), mx, my))
    return failed(result, PlanFailure::kStartOutsideMap,
                  "StartOutsideMapBounds: Start Coordinates of" + coordinates(start_W) + " was outside bounds");
  if (!costmap_world_to_map(g, goal_W.x(), goal_W.y(), mx, my))
    return failed(result, PlanFailure::kGoalOutsideMap,
                  "GoalOutsideMapBounds: Goal Coordinates of" + coordinates(goal_W) + " was outside bounds");
  if (p.tolerance_m == 0 && costmap.cells[static_cast<std::size_t>(my) * g.nx + mx] == mapping::kCostLethal)
    return failed(result, PlanFailure::kGoalOccupied,
                  "GoalOccupied: Goal Coordinates of" + coordinates(goal_W) + " was in lethal cost");
  if (start_W.x() == goal_W.x() && start_W.y() == goal_W.y()) {  // one pose: the start
    result.found = true;
    result.path_W = {start_W};
    return result;
  }
  const std::string no_path =
      "NoValidPathCouldBeFound: Failed to create plan with tolerance of: " + std::to_string(p.tolerance_m);

  // makePlan: the robot's cell (rounded) is cleared; NavFn's goal is the robot, its start the goal.
  int start_mx = 0, start_my = 0;
  planner_world_to_map(g, start_W.x(), start_W.y(), start_mx, start_my);
  const long robot_index = static_cast<long>(start_my) * g.nx + start_mx;
  if (robot_index >= ns)  // the start rounds up past the last row: nav2 writes outside its arrays here
    return failed(result, PlanFailure::kStartOutsideMap,
                  "StartOutsideMapBounds: Start Coordinates of" + coordinates(start_W) +
                      " round to a cell past the grid (nav2: out-of-bounds write)");
  std::vector<std::uint8_t> cells = costmap.cells;
  cells[static_cast<std::size_t>(robot_index)] = mapping::kCostFree;  // clearRobotCell
  NavFn nav(g.nx, g.ny);
  nav.set_costmap(cells.data(), p.allow_unknown);
  int goal_mx = 0, goal_my = 0;
  planner_world_to_map(g, goal_W.x(), goal_W.y(), goal_mx, goal_my);
  nav.set_start(goal_mx, goal_my);
  nav.set_goal(start_mx, start_my);
  if (p.use_astar) nav.calc_astar();
  else nav.calc_dijkstra(true);
  result.propagation_cycles = nav.cycles();

  // getPointPotential: max double outside the grid.
  auto point_potential = [&](const Eigen::Vector2d& w) {
    int x = 0, y = 0;
    if (!planner_world_to_map(g, w.x(), w.y(), x, y)) return std::numeric_limits<double>::max();
    return static_cast<double>(nav.potential_at(y * g.nx + x));
  };
  // The goal, or the reached point of the tolerance square (resolution steps from goal - tolerance) nearest to it;
  // the first in row order wins a tie.
  Eigen::Vector2d best = goal_W;
  bool found_legal = false;
  double potential = point_potential(goal_W);
  if (potential < kPotHighD) {
    found_legal = true;
  } else {
    double best_sdist = std::numeric_limits<double>::max();
    Eigen::Vector2d q = goal_W;
    q.y() = goal_W.y() - p.tolerance_m;
    while (q.y() <= goal_W.y() + p.tolerance_m) {
      q.x() = goal_W.x() - p.tolerance_m;
      while (q.x() <= goal_W.x() + p.tolerance_m) {
        potential = point_potential(q);
        const double sdist = squared_distance(q, goal_W);
        if (potential < kPotHighD && sdist < best_sdist) {
          best_sdist = sdist;
          best = q;
          found_legal = true;
        }
        q.x() += g.resolution_m;
      }
      q.y() += g.resolution_m;
    }
  }
  if (!found_legal) return failed(result, PlanFailure::kNoValidPath, no_path);
  result.goal_used_W = best;
  result.goal_potential = static_cast<float>(point_potential(best));

  // getPlanFromPotential: calcPath from the chosen goal's cell, 4 * the larger side cycles, reversed into world.
  int best_mx = 0, best_my = 0;
  planner_world_to_map(g, best.x(), best.y(), best_mx, best_my);
  nav.set_start(best_mx, best_my);
  const int path_len = nav.calc_path(4 * std::max(g.nx, g.ny));
  result.path_steps = path_len;
  if (path_len == 0)  // nav2 logs "Failed to create a plan from potential when a legal potential was found"
    return failed(result, PlanFailure::kNoValidPath, no_path);
  std::vector<Eigen::Vector2d>& plan = result.path_W;
  plan.reserve(static_cast<std::size_t>(path_len) + 1);
  for (int i = path_len - 1; i >= 0; --i)  // mapToWorld: origin + index * resolution, no half-cell offset
    plan.emplace_back(g.origin_x_m + static_cast<double>(nav.path_x()[i]) * g.resolution_m,
                      g.origin_y_m + static_cast<double>(nav.path_y()[i]) * g.resolution_m);

  // smoothApproachToGoal with the chosen goal.
  bool replaced = false;
  if (plan.size() >= 2) {
    const Eigen::Vector2d second_to_last = plan[plan.size() - 2];
    if (squared_distance(plan.back(), second_to_last) > squared_distance(best, second_to_last) ||
        squared_distance(plan.back(), best) < 1e-6) {
      plan.back() = best;
      replaced = true;
    }
  }
  if (!replaced) plan.push_back(best);

  if (p.use_final_approach_orientation && plan.size() > 1) {
    const std::size_t n = plan.size();
    Eigen::Vector2d approach = plan[n - 2];
    if (std::abs(plan.back().x() - approach.x()) < 0.0001 && std::abs(plan.back().y() - approach.y()) < 0.0001 && n > 2)
      approach = plan[n - 3];
    result.final_yaw = std::atan2(plan.back().y() - approach.y(), plan.back().x() - approach.x());
  }
  result.found = true;
  return result;
}

double path_length_m(const std::vector<Eigen::Vector2d>& path_W) {
  double length = 0;
  for (std::size_t i = 1; i < path_W.size(); ++i) length += (path_W[i] - path_W[i - 1]).norm();
  return length;
}

}  // namespace stvl::navigation
