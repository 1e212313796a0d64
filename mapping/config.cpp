#include "mapping/config.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "common/enum_names.hpp"

namespace stvl::mapping {
namespace {

[[noreturn]] void reject(const std::string& field, double value, const std::string& rule) {
  std::ostringstream message;
  message << field << " = " << value << " is invalid: " << rule;
  throw std::invalid_argument(message.str());
}

void require_finite(const char* field, double value) {
  if (!std::isfinite(value)) reject(field, value, "must be finite");
}

}  // namespace

namespace {
// STVL's numeric codes are accepted too: "0", "1", "-1" and "2" (see config.hpp).
constexpr EnumName<DecayModel> kDecayModelNames[] = {
    {DecayModel::kLinear, "linear"}, {DecayModel::kExponential, "exponential"}, {DecayModel::kPersistent, "persistent"},
    {DecayModel::kLinear, "0"},      {DecayModel::kExponential, "1"},           {DecayModel::kPersistent, "-1"},
    {DecayModel::kPersistent, "2"}};
}  // namespace

DecayModel parse_decay_model(const std::string& text) { return parse_enum(text, kDecayModelNames, "decay_model"); }
std::string to_string(DecayModel model) { return enum_name(model, kDecayModelNames); }

namespace {
constexpr EnumName<ClearingMode> kClearingModeNames[] = {{ClearingMode::kFrustum, "frustum"},
                                                         {ClearingMode::kRaycast, "raycast"}};
constexpr EnumName<ClearingWalk> kClearingWalkNames[] = {{ClearingWalk::kBounded, "bounded"},
                                                         {ClearingWalk::kFullWalk, "full_walk"}};
constexpr EnumName<MarkRounding> kMarkRoundingNames[] = {{MarkRounding::kFloor, "floor"},
                                                         {MarkRounding::kStvl, "stvl"}};
constexpr EnumName<FrustumGeometry> kFrustumGeometryNames[] = {{FrustumGeometry::kIdeal, "ideal"},
                                                               {FrustumGeometry::kStvl, "stvl"}};
constexpr EnumName<SensorFrame> kSensorFrameNames[] = {{SensorFrame::kOptical, "optical"},
                                                       {SensorFrame::kLink, "link"}};
}  // namespace

SensorFrame parse_sensor_frame(const std::string& text) { return parse_enum(text, kSensorFrameNames, "sensor_frame"); }
std::string to_string(SensorFrame frame) { return enum_name(frame, kSensorFrameNames); }

constexpr EnumName<ZReference> kZReferenceNames[] = {{ZReference::kGlobal, "global"},
                                                     {ZReference::kBaseLink, "base_link"}};
ZReference parse_z_reference(const std::string& text) {
  return parse_enum(text, kZReferenceNames, "z_reference_frame");
}
std::string to_string(ZReference frame) { return enum_name(frame, kZReferenceNames); }

Eigen::Isometry3d T_optical_sensor(SensorFrame frame) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  if (frame == SensorFrame::kLink)  // link x = optical z, link y = -optical x, link z = -optical y
    T.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  return T;
}

ClearingMode parse_clearing_mode(const std::string& text) {
  return parse_enum(text, kClearingModeNames, "clearing_mode");
}
std::string to_string(ClearingMode mode) { return enum_name(mode, kClearingModeNames); }
constexpr EnumName<UpdateGrouping> kUpdateGroupingNames[] = {{UpdateGrouping::kInstant, "instant"},
                                                             {UpdateGrouping::kCameraFrame, "camera_frame"}};
UpdateGrouping parse_update_grouping(const std::string& text) {
  return parse_enum(text, kUpdateGroupingNames, "update_grouping");
}
std::string to_string(UpdateGrouping grouping) { return enum_name(grouping, kUpdateGroupingNames); }
constexpr EnumName<CostmapBand> kCostmapBandNames[] = {{CostmapBand::kEveryVoxel, "every_voxel"},
                                                       {CostmapBand::kMarkingBand, "marking_band"}};
CostmapBand parse_costmap_band(const std::string& text) { return parse_enum(text, kCostmapBandNames, "costmap_band"); }
std::string to_string(CostmapBand band) { return enum_name(band, kCostmapBandNames); }
constexpr EnumName<CostmapTiming> kCostmapTimingNames[] = {{CostmapTiming::kStvl, "stvl"},
                                                           {CostmapTiming::kAfterMark, "after_mark"}};
CostmapTiming parse_costmap_timing(const std::string& text) {
  return parse_enum(text, kCostmapTimingNames, "costmap_timing");
}
std::string to_string(CostmapTiming timing) { return enum_name(timing, kCostmapTimingNames); }
ClearingWalk parse_clearing_walk(const std::string& text) {
  return parse_enum(text, kClearingWalkNames, "clearing_walk");
}
std::string to_string(ClearingWalk walk) { return enum_name(walk, kClearingWalkNames); }
MarkRounding parse_mark_rounding(const std::string& text) {
  return parse_enum(text, kMarkRoundingNames, "mark_rounding");
}
std::string to_string(MarkRounding rounding) { return enum_name(rounding, kMarkRoundingNames); }
FrustumGeometry parse_frustum_geometry(const std::string& text) {
  return parse_enum(text, kFrustumGeometryNames, "frustum_geometry");
}
std::string to_string(FrustumGeometry geometry) { return enum_name(geometry, kFrustumGeometryNames); }

void StvlConfig::validate() const {
  require_finite("voxel_size", voxel_size_m);
  if (!(voxel_size_m >= 0.01 && voxel_size_m <= 1.0)) reject("voxel_size", voxel_size_m, "must lie in [0.01, 1.0] m");
  require_finite("voxel_decay", voxel_decay_s);
  if (voxel_decay_s < 0.0) reject("voxel_decay", voxel_decay_s, "must be >= 0 s");
  const int model = static_cast<int>(decay_model);
  if (model != 0 && model != 1 && model != -1)
    reject("decay_model", model, "must be linear, exponential or persistent");
  if (mark_threshold < 0) reject("mark_threshold", mark_threshold, "must be >= 0");
  require_finite("update_frequency", update_frequency_hz);
  if (update_frequency_hz < 0.0 || update_frequency_hz > 1000.0)
    reject("update_frequency", update_frequency_hz, "must lie in [0, 1000] Hz (0: an update per camera instant)");
  if (clearing_mode != ClearingMode::kFrustum && clearing_mode != ClearingMode::kRaycast)
    reject("clearing_mode", static_cast<int>(clearing_mode), "must be frustum or raycast");
  if (clearing_walk != ClearingWalk::kBounded && clearing_walk != ClearingWalk::kFullWalk)
    reject("clearing_walk", static_cast<int>(clearing_walk), "must be bounded or full_walk");
  if (mark_rounding != MarkRounding::kFloor && mark_rounding != MarkRounding::kStvl)
    reject("mark_rounding", static_cast<int>(mark_rounding), "must be floor or stvl");
  if (frustum_geometry != FrustumGeometry::kIdeal && frustum_geometry != FrustumGeometry::kStvl)
    reject("frustum_geometry", static_cast<int>(frustum_geometry), "must be ideal or stvl");
  if (expiry_leaves_per_update < 1)
    reject("expiry_leaves_per_update", static_cast<double>(expiry_leaves_per_update), "must be >= 1");
  if (!footprint_B.empty() && footprint_B.size() < 3)
    reject("footprint", static_cast<double>(footprint_B.size()), "needs at least three points (or none)");
  for (const auto& p : footprint_B)
    if (!p.allFinite()) reject("footprint", p.x() + p.y(), "points must be finite");
  require_finite("clear_footprint_voxels_below", clear_footprint_voxels_below_m);
  if (clear_footprint_voxels_below_m < 0.0 || clear_footprint_voxels_below_m > 3.0)
    reject("clear_footprint_voxels_below", clear_footprint_voxels_below_m, "must lie in [0, 3] m");
  if (clear_footprint_voxels_below_m > 0.0 && footprint_B.empty())
    reject("clear_footprint_voxels_below", clear_footprint_voxels_below_m,
           "needs the robot's footprint (robot_radius or footprint)");
}

void ObservationSource::validate() const {
  require_finite("obstacle_range", obstacle_range_m);
  if (obstacle_range_m <= 0.0) reject("obstacle_range", obstacle_range_m, "must be > 0 m");
  require_finite("min_obstacle_height", min_obstacle_height_m);
  require_finite("max_obstacle_height", max_obstacle_height_m);
  if (min_obstacle_height_m > max_obstacle_height_m)
    reject("min_obstacle_height", min_obstacle_height_m,
           "must be <= max_obstacle_height = " + std::to_string(max_obstacle_height_m));
  constexpr double kPi = 3.14159265358979323846;
  require_finite("horizontal_fov_angle", horizontal_fov_rad);
  if (model == ClearingModel::kLidar3D) {  // STVL's lidar model: more than 6.27 rad is the full circle
    if (!(horizontal_fov_rad > 0.0 && horizontal_fov_rad <= 6.3))
      reject("horizontal_fov_angle", horizontal_fov_rad, "must lie in (0, 6.3] rad with model_type 1");
  } else if (!(horizontal_fov_rad > 0.0 && horizontal_fov_rad < kPi)) {
    reject("horizontal_fov_angle", horizontal_fov_rad, "must lie in (0, pi) rad");
  }
  if (model != ClearingModel::kDepthCamera && model != ClearingModel::kLidar3D)
    reject("model_type", static_cast<double>(model), "STVL knows 0 (depth camera) and 1 (3D lidar)");
  require_finite("vertical_fov_padding", vertical_fov_padding_m);
  if (vertical_fov_padding_m < 0.0) reject("vertical_fov_padding", vertical_fov_padding_m, "must be >= 0 m");
  require_finite("vertical_fov_angle", vertical_fov_rad);
  if (!(vertical_fov_rad > 0.0 && vertical_fov_rad < kPi))
    reject("vertical_fov_angle", vertical_fov_rad, "must lie in (0, pi) rad");
  require_finite("min_z", min_z_m);
  require_finite("max_z", max_z_m);
  if (min_z_m < 0.0) reject("min_z", min_z_m, "must be >= 0 m");
  if (min_z_m >= max_z_m) reject("min_z", min_z_m, "must be < max_z = " + std::to_string(max_z_m));
  require_finite("decay_acceleration", decay_acceleration_per_s3);
  if (decay_acceleration_per_s3 < 0.0) reject("decay_acceleration", decay_acceleration_per_s3, "must be >= 0");
  require_finite("expected_update_rate", expected_update_rate_s);
  if (expected_update_rate_s < 0.0)
    reject("expected_update_rate", expected_update_rate_s, "must be >= 0 s (0: never checked)");
  require_finite("observation_persistence", observation_persistence_s);
  if (observation_persistence_s < 0.0)
    reject("observation_persistence", observation_persistence_s, "must be >= 0 s (0: the latest reading only)");
}

}  // namespace stvl::mapping
