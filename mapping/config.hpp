#pragma once
// Parameters of the spatio-temporal voxel map. Field names and defaults follow STVL's ROS parameters
// (spatio_temporal_voxel_layer.cpp); where we differ the comment says so. Lengths in metres, angles in
// radians, times in seconds of simulated time.
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace stvl::mapping {

// STVL's integer codes are kept: 0 linear, 1 exponential, -1 persistent. STVL documents -1 for persistent,
// its enum says PERSISTENT = 2 and its decay function treats every code but 0 and 1 as persistent; here
// -1 and 2 both mean persistent and any other code is rejected instead of silently becoming persistent.
enum class DecayModel { kLinear = 0, kExponential = 1, kPersistent = -1 };

// Accepts "linear" | "exponential" | "persistent" and "0" | "1" | "-1" | "2"; throws std::invalid_argument.
DecayModel parse_decay_model(const std::string& text);
std::string to_string(DecayModel model);

// frustum: STVL's decay acceleration inside the clearing frustums.
// raycast: free space between the sensor and each point is cleared outright (what STVL cannot do).
enum class ClearingMode { kFrustum, kRaycast };
ClearingMode parse_clearing_mode(const std::string& text);
std::string to_string(ClearingMode mode);

// bounded: visit only leaf nodes whose bounding boxes meet a clearing frustum, plus an expiry index that
//          removes at most `expiry_leaves_per_update` leaves of expired voxels elsewhere per update.
// full_walk: STVL's behaviour, every active voxel visited on every update (the in-run baseline).
enum class ClearingWalk { kBounded, kFullWalk };
ClearingWalk parse_clearing_walk(const std::string& text);
std::string to_string(ClearingWalk walk);

// How mark() turns a point into a voxel key (only marking; lookup() and key_of() always floor).
// floor (the bench's): key = floor(p / voxel_size) on every axis, so key k spans [k*s, (k+1)*s).
// stvl: STVL's arithmetic (grid.cpp operator(), ros2 403d9ed and noetic-devel 5e06daf), in double with
//   vs = double(float(voxel_size)): x' = px < 0 ? px - vs : px, y' = py < 0 ? py - vs : py,
//   z' = py < 0 ? pz - vs : pz (the sign of *y*: STVL's bug), key = trunc(x' * (1.0 / vs)) per axis (the
//   conversion to openvdb::Coord). For py >= 0, key z = 0 covers (-vs, vs); for py < 0, positive z lands one
//   voxel lower than with floor; an exact negative multiple of vs lands one voxel further out.
enum class MarkRounding { kFloor, kStvl };
MarkRounding parse_mark_rounding(const std::string& text);
std::string to_string(MarkRounding rounding);

// The depth camera's clearing frustum (mapping/frustum.hpp), in both walks.
// ideal (the bench's): near/far planes at z = min_z / max_z, sides |x| <= z tan(h/2), |y| <= z tan(v/2).
// stvl: STVL's DepthCameraFrustum::ComputePlaneNormals (ros2 403d9ed, noetic-devel 5e06daf): corners at radial
//   distance min_z / max_z along the unit rays Rx(+-v/2) Ry(+-h/2) z, so near/far planes at
//   d cos(h/2) cos(v/2) and sides |x| <= z tan(h/2) / cos(v/2), |y| <= z tan(v/2); a voxel centre
//   c = i*vs + vs/2 (vs = double(float(voxel_size))) is outside iff dot(n, normalize(c - anchor)) > 0 for some
//   outward plane normal n (on a plane counts as inside).
enum class FrustumGeometry { kIdeal, kStvl };
FrustumGeometry parse_frustum_geometry(const std::string& text);
std::string to_string(FrustumGeometry geometry);

// Which camera frames make one STVL update (layer/stvl_layer.hpp).
// instant: STVL's layer takes every source's readings in one update (one ClearFrustums with every clearing
//   reading, a voxel accelerated once, by the first frustum that holds it; then one Mark): the frames of cameras
//   that share a time make one update, at the last of them.
// camera_frame (the bench before 2026-12): one clear-and-mark update per camera frame, so a voxel in two
//   cameras' frustums at one instant is accelerated twice.
enum class UpdateGrouping { kInstant, kCameraFrame };
UpdateGrouping parse_update_grouping(const std::string& text);
std::string to_string(UpdateGrouping grouping);

// Which voxels of a column count toward its costmap cell (the map's projection and the evaluation's).
// every_voxel: STVL's (TemporalClearAndGenerateCostmap counts every voxel that survives, whatever its height;
//   heights are limited only by the marking filter, on the points).
// marking_band (the bench before 2026-12-03): only voxels whose centre z lies in the marking sources'
//   [min_obstacle_height, max_obstacle_height]; with STVL's z shift a low obstacle's voxel can fall under it.
enum class CostmapBand { kEveryVoxel, kMarkingBand };
CostmapBand parse_costmap_band(const std::string& text);
std::string to_string(CostmapBand band);

// When the costmap (project_costmap, for_each_column) sees an update's marks.
// stvl: STVL builds its 2D costmap during ClearFrustums, before Mark (layer.cpp updateBounds, ros2 403d9ed and
//   noetic-devel 5e06daf), and publishes that: voxels that mark() created since the last clear() are not
//   counted, so an update's new obstacles reach the costmap one update later (refreshed voxels count at once).
// after_mark (the bench before 2026-12-03): the costmap counts every voxel in the map.
enum class CostmapTiming { kStvl, kAfterMark };
CostmapTiming parse_costmap_timing(const std::string& text);
std::string to_string(CostmapTiming timing);

struct StvlConfig {
  // Accepted range [0.01, 1.0] m (STVL's usable range is 0.02..0.2): below 1 cm one 10 m frustum holds
  // over 10^9 voxels; above 1 m the map is useless for a ground robot.
  double voxel_size_m = 0.05;  // YAML voxel_size
  // STVL declares -1.0 (which makes linear voxels expire at once); negative values are rejected here and
  // the default is the 15 s used in STVL's example configuration.
  double voxel_decay_s = 15.0;  // YAML voxel_decay
  DecayModel decay_model = DecayModel::kLinear;
  // A costmap cell is lethal where its column holds >= max(mark_threshold, 1) voxels (STVL compares
  // count >= mark_threshold over columns that hold at least one voxel, so 0 behaves like 1).
  int mark_threshold = 0;
  ClearingMode clearing_mode = ClearingMode::kFrustum;
  ClearingWalk clearing_walk = ClearingWalk::kBounded;
  MarkRounding mark_rounding = MarkRounding::kStvl;           // YAML map.mark_rounding; floor is the bench's
  FrustumGeometry frustum_geometry = FrustumGeometry::kStvl;  // YAML map.frustum_geometry; ideal is the bench's
  UpdateGrouping update_grouping = UpdateGrouping::kInstant;  // YAML map.update_grouping; camera_frame is the bench's
  CostmapBand costmap_band = CostmapBand::kEveryVoxel;        // YAML map.costmap_band; marking_band is the bench's
  CostmapTiming costmap_timing = CostmapTiming::kStvl;        // YAML map.costmap_timing; after_mark is the bench's
  // nav2's costmap update_frequency (YAML map.update_frequency, or the costmap's own key in a ROS parameter file):
  // STVL's layer updates at every tick k / update_frequency_hz, frames or not (the ticks since the last frame run
  // when the next frame arrives, at their own times), applying every source's buffer (persistence 0: its newest
  // reading, marked again with the update's time); frames in between only fill the buffers. 0 (the default of
  // native scenarios): an update at every instant with frames.
  double update_frequency_hz = 0.0;
  // Bound on expiry work per update in bounded mode; a backlog larger than this is worked off over the next
  // updates (lag = ceil(backlog / expiry_leaves_per_update) updates).
  std::size_t expiry_leaves_per_update = 256;
  // update_footprint_enabled (STVL's default true): each costmap projection frees the cells of the footprint's
  // convex fill at the robot's pose (mapping/footprint.hpp); the voxels stay. footprint_B: the robot's
  // polygon in base_link (nav2's `footprint`, or footprint_from_radius(`robot_radius`)); empty = none, and then
  // nothing is cleared (nav2 would fall back to its robot_radius default of 0.1 m).
  bool update_footprint_enabled = true;
  std::vector<Eigen::Vector2d> footprint_B;
  // clear_footprint_voxels_below (the bench's; STVL has none, 0 = off): at every update, after marking, the voxels in
  // the footprint's convex fill at the robot's pose from the floor up to this height are removed from the map,
  // so that the robot's own body (a bumper, a mast in view) leaves no voxels behind when it drives on. Voxels
  // above it (a desk top the robot passes under) stay. Needs footprint_B.
  double clear_footprint_voxels_below_m = 0.0;

  void validate() const;  // throws std::invalid_argument naming the offending field and value
};

// One observation source (STVL: a sensor topic). The clearing frustum is a depth camera's: apex at the
// optical centre, z forward, x right, y down.
// The clearing volume a source builds (model_type): STVL's DepthCameraFrustum (0) or ThreeDimensionalLidarFrustum
// (1, mapping/lidar_frustum.hpp).
enum class ClearingModel { kDepthCamera = 0, kLidar3D = 1 };
// The frame STVL builds the clearing volume in (sensor_frame): the cloud's own (the camera's optical frame, z
// forward; STVL's default, sensor_frame empty) or the camera's link (x forward, z up: <camera>_link).
enum class SensorFrame { kOptical, kLink };
SensorFrame parse_sensor_frame(const std::string& text);  // "optical" | "link"; throws std::invalid_argument
std::string to_string(SensorFrame frame);
// The frame whose z the height band is measured in (z_reference_frame, STVL's passthrough_relative and
// voxel_relative filters, PR #304 / 22f7927): the map's (global, STVL's passthrough and voxel) or the robot's
// base_link. Relative: STVL's buffer takes the cloud into base_link (float), filters there (band, and the voxel
// leaves for voxel_relative) and takes what is left to the global frame (float again): pipeline/sensing.cpp.
enum class ZReference { kGlobal, kBaseLink };
ZReference parse_z_reference(const std::string& text);  // "global" | "base_link"; throws std::invalid_argument
std::string to_string(ZReference frame);
// The rotation from the sensor frame to the optical frame (identity for kOptical).
Eigen::Isometry3d T_optical_sensor(SensorFrame frame);

struct ObservationSource {
  bool marking = true;
  bool clearing = false;
  // Field (YAML key): meaning.
  double obstacle_range_m = 2.5;  // obstacle_range: points farther than this from the optical centre are not marked
  double min_obstacle_height_m = 0.0;  // min_obstacle_height: world z band for marking, inclusive
  double max_obstacle_height_m = 3.0;  // max_obstacle_height
  // Whether the band above applies (no YAML key): STVL's buffer applies it through its passthrough or voxel
  // filter; a ROS parameter file's `filter` none (any other string) applies none, and every height marks.
  bool height_band = true;
  // z_reference_frame: the frame the band's z is in. With base_link, mark() applies no band itself: the source's
  // buffer cloud (pipeline::source_marking_W) was banded in base_link before.
  ZReference z_reference = ZReference::kGlobal;
  double horizontal_fov_rad = 1.04;                   // horizontal_fov_angle: full angle, (0, pi)
  double vertical_fov_rad = 0.7;                      // vertical_fov_angle: full angle, (0, pi)
  double min_z_m = 0.0;                               // min_z: frustum near plane along the optical axis, >= 0
  double max_z_m = 10.0;                              // max_z: frustum far plane (and the ray-cast clearing range)
  double decay_acceleration_per_s3 = 0.0;             // decay_acceleration: >= 0, 1/s^3
  ClearingModel model = ClearingModel::kDepthCamera;  // model_type: 0 or 1; with 1, horizontal_fov_angle up to 2 pi
  double vertical_fov_padding_m = 0.0;  // vertical_fov_padding: >= 0, model_type 1 only (shrinks the cone by metres)
  SensorFrame sensor_frame = SensorFrame::kOptical;  // sensor_frame: optical | link (ROS files: the frame's name)
  // clear_on_no_return (the bench's; STVL clears nothing along a pixel that returns nothing): in ray-cast mode the rays
  // of pixels without a return are walked to max_z too. A camera cannot tell "too far" from a dropout or a
  // too-near obstacle, so this also clears what such pixels hide.
  bool clear_on_no_return = false;
  // STVL's measurement buffer (measurement_buffer.cpp). expected_update_rate is a period in seconds, as STVL and
  // costmap_2d read it (not a rate in Hz): the source is not current when its last reading is older than this;
  // 0 = never checked. observation_persistence: readings are kept this long before the source's last reading
  // (not before now: during an outage nothing is dropped) and applied again at every map update; 0 = the
  // latest only, which STVL keeps and applies again at every update until a new one arrives.
  double expected_update_rate_s = 0.0;     // expected_update_rate: >= 0 s
  double observation_persistence_s = 0.0;  // observation_persistence: >= 0 s
  // drop_when_not_current (the bench's; STVL applies a stale buffer at every update): while the source is not current
  // (expected_update_rate exceeded) its buffered readings are not applied again at other cameras' updates.
  bool drop_when_not_current = false;

  void validate() const;
};

}  // namespace stvl::mapping
