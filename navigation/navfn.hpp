#pragma once
// nav2's NavFn global planner (planner_server plugin nav2_navfn_planner::NavfnPlanner), reproduced from
// ros-navigation/navigation2 jazzy f4108e5:
//   - nav2_navfn_planner/src/navfn.cpp, include/nav2_navfn_planner/navfn.hpp: the NavFn class (setCostmap,
//     setupNavFn, the Dijkstra and A* propagations with their priority buffers, updateCell, calcPath, gradCell);
//   - nav2_navfn_planner/src/navfn_planner.cpp: createPlan / makePlan (start and goal swapped, tolerance search,
//     getPlanFromPotential, smoothApproachToGoal, use_final_approach_orientation).
// Positions in the costmap's world frame; NavfnPlanner's own worldToMap rounds (cell i at origin + i * resolution),
// unlike Costmap2D::worldToMap, which floors; both are reproduced where nav2 uses them.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "mapping/costmap.hpp"

namespace stvl::navigation {

// The GridBased (nav2_navfn_planner) keys with nav2 jazzy's defaults (NavfnPlanner::configure).
struct NavfnParams {
  double tolerance_m = 0.5;                     // tolerance
  bool use_astar = false;                       // use_astar
  bool allow_unknown = true;                    // allow_unknown
  bool use_final_approach_orientation = false;  // use_final_approach_orientation
  // Throws std::invalid_argument naming tolerance when it is negative or not finite.
  void validate() const;
};

// nav2_core's exceptions that NavfnPlanner::createPlan throws, as values.
enum class PlanFailure { kNone, kStartOutsideMap, kGoalOutsideMap, kGoalOccupied, kNoValidPath };

struct PlanResult {
  bool found = false;
  std::vector<Eigen::Vector2d> path_W;  // start to goal, as nav_msgs/Path positions, the (tolerance) goal last
  PlanFailure failure_kind = PlanFailure::kNone;
  std::string failure;                                    // nav2's exception name and message when !found
  Eigen::Vector2d goal_used_W = Eigen::Vector2d::Zero();  // the goal or the point the tolerance search chose
  float goal_potential = 0.0f;                            // NavFn potential at goal_used_W (1e10: never reached)
  int propagation_cycles = 0;                             // cycles of the Dijkstra / A* loop
  int path_steps = 0;                                     // calcPath's points (0 when it failed)
  // use_final_approach_orientation: the yaw nav2 gives the last pose (direction of the last path step). Unset
  // otherwise (nav2 keeps the goal's orientation) and for start == goal's one-pose plan (nav2: the goal's orientation,
  // or the start's with use_final_approach_orientation); orientations are not inputs here.
  std::optional<double> final_yaw;
};

// NavfnPlanner::createPlan from start_W to goal_W on `costmap` (the master costmap, inflation applied). Failures come
// back in the result, not as exceptions. The robot's cell is cleared in a copy, not in `costmap`. Throws
// std::invalid_argument for invalid params or a costmap whose cells do not match its size.
PlanResult navfn_plan(const mapping::Costmap2D& costmap, const Eigen::Vector2d& start_W, const Eigen::Vector2d& goal_W,
                      const NavfnParams& p);

// The length of a plan: the sum of its segments (m).
double path_length_m(const std::vector<Eigen::Vector2d>& path_W);

// NavFn's cell costs (navfn.hpp's defines).
constexpr std::uint8_t kNavfnCostNeutral = 50;  // COST_NEUTRAL
constexpr std::uint8_t kNavfnCostObs = 254;     // COST_OBS
constexpr float kNavfnPotHigh = 1.0e10f;        // POT_HIGH

// NavFn::setCostmap's translation of one costmap value (isROS): < 253 -> 50 + 0.8 * v truncated (at most 253),
// 253 and 254 -> 254, 255 -> 253 if allow_unknown else 254.
std::uint8_t navfn_cost(std::uint8_t costmap_cost, bool allow_unknown);

// nav2's NavFn on one grid, for the planner and for tests. "goal" is where the potential is 0 and "start" where the
// propagation stops and calcPath begins; navfn_plan passes the robot cell as goal and the goal cell as start.
class NavFn {
 public:
  NavFn(int nx, int ny);
  // setCostmap(cmap, true, allow_unknown): `cells` holds nx * ny costmap values, row 0 first.
  void set_costmap(const std::uint8_t* cells, bool allow_unknown);
  void set_goal(int x, int y) { goal_[0] = x, goal_[1] = y; }
  void set_start(int x, int y) { start_[0] = x, start_[1] = y; }
  // calcNavFnDijkstra / calcNavFnAstar: setupNavFn, then the propagation; true unless the cycle limit ran out
  // (Dijkstra) / true when the start cell was reached (A*).
  bool calc_dijkstra(bool at_start);
  bool calc_astar();
  // calcPath(n) from the start cell: the number of points, 0 on failure.
  int calc_path(int max_cycles);

  int nx() const { return nx_; }
  int ny() const { return ny_; }
  std::uint8_t cost(int x, int y) const { return cost_[static_cast<std::size_t>(y) * nx_ + x]; }
  float potential(int x, int y) const { return pot_[y * nx_ + x]; }
  float potential_at(int index) const { return pot_[index]; }
  const float* potentials() const { return pot_; }              // nx * ny, row 0 first
  const std::vector<float>& path_x() const { return path_x_; }  // calcPath's points in cells, start to goal
  const std::vector<float>& path_y() const { return path_y_; }
  int cycles() const { return cycles_; }
  float last_path_cost() const { return last_path_cost_; }  // A* only, as nav2

 private:
  void setup();
  void init_cost(int k, float v);
  template <bool kAstar>
  void update_cell(int n);
  template <bool kAstar>
  bool propagate(int cycles, bool at_start);
  float grad_cell(int n);
  void push(int which, int n);

  int nx_, ny_, ns_, pad_;
  std::vector<std::uint8_t> cost_;
  // Potential and gradients with pad_ cells either side: nav2 reads (and gradCell writes) a row past either end of
  // its arrays in some border cases; here those cells hold POT_HIGH / 0 instead of whatever the heap held.
  std::vector<float> pot_store_, gradx_store_, grady_store_;
  float* pot_;
  float* gradx_;
  float* grady_;
  std::vector<std::uint8_t> pending_;
  std::vector<int> buf_[3];  // pb1, pb2, pb3
  int* cur_p_;
  int* next_p_;
  int* over_p_;
  int cur_pe_ = 0, next_pe_ = 0, over_pe_ = 0;
  float cur_t_ = 0.0f;
  float pri_inc_;
  int goal_[2] = {0, 0};
  int start_[2] = {0, 0};
  int cycles_ = 0;
  float last_path_cost_ = 0.0f;
  float path_step_ = 0.5f;
  std::vector<float> path_x_, path_y_;
};

}  // namespace stvl::navigation
