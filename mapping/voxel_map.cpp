// VoxelMap's core: the grid, marking, lookups and keys, the clear() dispatch and the costmap projection. Decay and
// expiry live in voxel_map_decay.cpp, ray-cast clearing in voxel_map_raycast.cpp, .vdb/.ply in voxel_map_io.cpp.
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "mapping/detail/voxel_map_impl.hpp"
#include "mapping/footprint.hpp"
#include "mapping/frustum.hpp"

namespace stvl::mapping {

using detail::Coord;
using detail::Frustum;
using detail::kBackground;
using detail::kGridName;
using detail::leaf_origin;

namespace {

constexpr double kMinMarkDistanceSq_m2 = 1e-4;  // STVL skips points within 1 cm of the sensor

}  // namespace

namespace detail {

void ensure_openvdb_initialized() {
  static const bool initialized = [] {
    openvdb::initialize();
    return true;
  }();
  (void)initialized;
}

}  // namespace detail

VoxelMap::Impl::Impl(const StvlConfig& map_config) : config(map_config) {
  detail::ensure_openvdb_initialized();
  grid = GridT::create(kBackground);
  grid->setName(kGridName);
  auto transform = openvdb::math::Transform::createLinearTransform(config.voxel_size_m);
  transform->postTranslate(openvdb::Vec3d(config.voxel_size_m / 2));
  grid->setTransform(transform);
}

void VoxelMap::Impl::check_time(double time_s) {
  if (!std::isfinite(time_s)) throw std::invalid_argument("time_s = " + std::to_string(time_s) + " is not finite");
  if (time_s < latest_time_s)
    throw std::invalid_argument("time_s = " + std::to_string(time_s) + " is earlier than the map's latest time " +
                                std::to_string(latest_time_s));
  latest_time_s = time_s;
}

VoxelMap::VoxelMap(const StvlConfig& config) {
  config.validate();
  impl_ = std::make_unique<Impl>(config);
}
VoxelMap::~VoxelMap() = default;
VoxelMap::VoxelMap(VoxelMap&&) noexcept = default;
VoxelMap& VoxelMap::operator=(VoxelMap&&) noexcept = default;

const StvlConfig& VoxelMap::config() const { return impl_->config; }
double VoxelMap::voxel_size_m() const { return impl_->config.voxel_size_m; }

std::size_t VoxelMap::mark(const Eigen::Matrix3Xf& points_W, const Eigen::Isometry3d& T_world_camera,
                           const ObservationSource& source, double time_s) {
  source.validate();
  validate_pose(T_world_camera);
  impl_->check_time(time_s);
  if (!source.marking) return 0;
  const Eigen::Vector3d origin_W = T_world_camera.translation();
  // STVL's range test (grid.cpp operator()): both squares rounded to float, the point's terms in double.
  const float range_sq_m2 = static_cast<float>(source.obstacle_range_m * source.obstacle_range_m);
  const bool indexed = impl_->uses_expiry_index();
  const double due_s = time_s + impl_->config.voxel_decay_s;
  const bool track_created = impl_->config.costmap_timing == CostmapTiming::kStvl;
  auto accessor = impl_->grid->getAccessor();
  Coord last_leaf(std::numeric_limits<int>::max());
  std::size_t marked = 0;
  for (Eigen::Index i = 0; i < points_W.cols(); ++i) {
    const Eigen::Vector3d p_W = points_W.col(i).cast<double>();
    if (!p_W.allFinite()) continue;
    const double dx = p_W.x() - origin_W.x(), dy = p_W.y() - origin_W.y(), dz = p_W.z() - origin_W.z();
    const float distance_sq_m2 = static_cast<float>(dx * dx + dy * dy + dz * dz);
    if (distance_sq_m2 > range_sq_m2 || distance_sq_m2 < kMinMarkDistanceSq_m2) continue;
    if (source.height_band && source.z_reference == ZReference::kGlobal &&
        (p_W.z() < source.min_obstacle_height_m || p_W.z() > source.max_obstacle_height_m))
      continue;
    Coord key;
    if (!impl_->mark_key(p_W, key)) continue;
    if (track_created && !accessor.isValueOn(key)) {
      const Coord leaf = leaf_origin(key), local = key - leaf;
      impl_->created_since_clear[leaf][local.x()] |= std::uint64_t{1} << (8 * local.y() + local.z());
    }
    accessor.setValueOn(key, time_s);
    ++marked;
    if (indexed) {
      const Coord leaf = leaf_origin(key);
      if (leaf != last_leaf) {
        impl_->schedule(leaf, due_s);
        last_leaf = leaf;
      }
    }
  }
  return marked;
}

ClearStats VoxelMap::clear(const std::vector<ClearingObservation>& observations, double time_s,
                           std::vector<VoxelKey>* cleared_keys, std::vector<VoxelKey>* removed_keys) {
  std::vector<ClearingObservation> clearing;
  for (const ClearingObservation& obs : observations) {
    obs.source.validate();
    validate_pose(obs.T_world_camera);
    if (!obs.source.clearing) continue;
    if (impl_->config.clearing_mode == ClearingMode::kRaycast && obs.points_W == nullptr)
      throw std::invalid_argument("clearing_mode = raycast needs ClearingObservation::points_W, got null");
    if (obs.source.clear_on_no_return && impl_->config.clearing_mode != ClearingMode::kRaycast)
      throw std::invalid_argument("clear_on_no_return needs clearing_mode = raycast");
    clearing.push_back(obs);
  }
  impl_->check_time(time_s);
  impl_->created_since_clear.clear();  // STVL's costmap of this update counts every voxel there is now
  ClearStats stats;
  std::vector<Frustum> frustums;
  if (impl_->config.clearing_mode == ClearingMode::kFrustum) {
    for (const ClearingObservation& obs : clearing) {
      const Eigen::Isometry3d T_world_sensor = obs.T_world_camera * T_optical_sensor(obs.source.sensor_frame);
      if (obs.source.model == ClearingModel::kLidar3D)
        frustums.push_back({LidarFrustum(T_world_sensor, obs.source), obs.source.decay_acceleration_per_s3});
      else
        frustums.push_back({DepthCameraFrustum(T_world_sensor, obs.source, impl_->config.frustum_geometry),
                            obs.source.decay_acceleration_per_s3});
    }
  } else {
    std::vector<VoxelKey> by_rays;  // what the rays removed is cleared and removed alike
    impl_->raycast_pass(clearing, stats, cleared_keys || removed_keys ? &by_rays : nullptr);
    for (std::vector<VoxelKey>* out : {cleared_keys, removed_keys})
      if (out) out->insert(out->end(), by_rays.begin(), by_rays.end());
  }
  if (impl_->config.clearing_walk == ClearingWalk::kFullWalk) {
    impl_->full_walk(frustums, time_s, stats, cleared_keys, removed_keys);
  } else {
    impl_->frustum_pass(frustums, time_s, stats, cleared_keys, removed_keys);
    impl_->expiry_pass(time_s, stats, removed_keys);
  }
  return stats;
}

std::size_t VoxelMap::size() const { return impl_->grid->activeVoxelCount(); }
std::size_t VoxelMap::leaf_count() const { return impl_->grid->tree().leafCount(); }

std::size_t VoxelMap::memory_bytes() const { return static_cast<std::size_t>(impl_->grid->tree().memUsage()); }

VoxelKey VoxelMap::key_of(const Eigen::Vector3d& p_W) const {
  Coord key;
  if (!p_W.allFinite() || !impl_->to_key(p_W, key))
    throw std::invalid_argument("point (" + std::to_string(p_W.x()) + ", " + std::to_string(p_W.y()) + ", " +
                                std::to_string(p_W.z()) + ") has no voxel key");
  return {key.x(), key.y(), key.z()};
}

VoxelKey VoxelMap::mark_key_of(const Eigen::Vector3d& p_W) const {
  Coord key;
  if (!p_W.allFinite() || !impl_->mark_key(p_W, key))
    throw std::invalid_argument("point (" + std::to_string(p_W.x()) + ", " + std::to_string(p_W.y()) + ", " +
                                std::to_string(p_W.z()) + ") has no voxel key");
  return {key.x(), key.y(), key.z()};
}

Eigen::Vector3d VoxelMap::center_of(const VoxelKey& key) const { return impl_->centre_W(Coord(key.x, key.y, key.z)); }

std::optional<double> VoxelMap::lookup(const Eigen::Vector3d& p_W) const {
  Coord key;
  if (!p_W.allFinite() || !impl_->to_key(p_W, key)) return std::nullopt;
  double value = 0.0;
  if (!impl_->grid->tree().probeValue(key, value)) return std::nullopt;
  return value;
}

std::vector<Voxel> VoxelMap::voxels() const {
  std::vector<Voxel> out;
  out.reserve(size());
  for (auto it = impl_->grid->cbeginValueOn(); it; ++it) {
    const Coord c = it.getCoord();
    out.push_back({{c.x(), c.y(), c.z()}, *it});
  }
  std::sort(out.begin(), out.end(), [](const Voxel& a, const Voxel& b) { return a.key < b.key; });
  return out;
}

std::vector<VoxelKey> VoxelMap::voxel_keys() const {
  std::vector<VoxelKey> keys;
  for (const Voxel& v : voxels()) keys.push_back(v.key);
  return keys;
}

bool VoxelMap::contains(const VoxelKey& key) const { return impl_->grid->tree().isValueOn(Coord(key.x, key.y, key.z)); }

void VoxelMap::for_each_key(const std::function<void(const VoxelKey&)>& visit) const {
  for (auto it = impl_->grid->cbeginValueOn(); it; ++it) {
    const Coord c = it.getCoord();
    visit({c.x(), c.y(), c.z()});
  }
}

void VoxelMap::for_each_leaf(const std::function<void(const VoxelKey&, const std::uint64_t*)>& visit) const {
  static_assert(detail::LeafT::DIM == 8 && detail::LeafT::NodeMaskType::WORD_COUNT == 8,
                "8^3 leaves, 8 words of 64 bits");
  std::uint64_t on[8];
  for (auto leaf = impl_->grid->tree().cbeginLeaf(); leaf; ++leaf) {
    const auto& mask = leaf->getValueMask();
    if (mask.isOff()) continue;
    for (int w = 0; w < 8; ++w) on[w] = mask.template getWord<std::uint64_t>(static_cast<openvdb::Index>(w));
    const Coord o = leaf->origin();
    visit({o.x(), o.y(), o.z()}, on);
  }
}

void VoxelMap::for_each_column(double min_z_m, double max_z_m,
                               const std::function<void(int x, int y, int voxels)>& visit) const {
  const double s = impl_->config.voxel_size_m;
  for (auto leaf = impl_->grid->tree().cbeginLeaf(); leaf; ++leaf) {
    const Coord o = leaf->origin();
    std::uint64_t band = 0;  // the z bits (8 words of 8 columns of 8 z bits) whose centres lie in the band
    for (int z = 0; z < 8; ++z) {
      const double z_m = (o.z() + z + 0.5) * s;
      if (z_m >= min_z_m && z_m <= max_z_m) band |= std::uint64_t{1} << z;
    }
    if (band == 0) continue;
    band *= 0x0101010101010101ull;  // the same z bits in every column of a word
    const auto& mask = leaf->getValueMask();
    const auto created = impl_->created_since_clear.find(o);
    for (int x = 0; x < 8; ++x) {  // word x holds the columns (x, y = 0..7)
      std::uint64_t in_band = mask.template getWord<std::uint64_t>(static_cast<openvdb::Index>(x)) & band;
      if (created != impl_->created_since_clear.end()) in_band &= ~created->second[static_cast<std::size_t>(x)];
      if (in_band == 0) continue;
      for (int y = 0; y < 8; ++y)
        if (const int n = __builtin_popcountll((in_band >> (8 * y)) & 0xffu)) visit(o.x() + x, o.y() + y, n);
    }
  }
}

void VoxelMap::for_each_key_in(const VoxelKey& lo, const VoxelKey& hi,
                               const std::function<void(const VoxelKey&)>& visit) const {
  if (lo.x > hi.x || lo.y > hi.y || lo.z > hi.z) return;
  const openvdb::CoordBBox box(Coord(lo.x, lo.y, lo.z), Coord(hi.x, hi.y, hi.z));
  for (auto leaf = impl_->grid->tree().cbeginLeaf(); leaf; ++leaf) {
    if (!box.hasOverlap(leaf->getNodeBoundingBox())) continue;
    for (auto it = leaf->cbeginValueOn(); it; ++it) {
      const Coord c = it.getCoord();
      if (box.isInside(c)) visit({c.x(), c.y(), c.z()});
    }
  }
}

Eigen::Matrix3Xf VoxelMap::voxel_centers() const {
  const auto keys = voxel_keys();
  Eigen::Matrix3Xf centres_W(3, static_cast<Eigen::Index>(keys.size()));
  for (std::size_t i = 0; i < keys.size(); ++i)
    centres_W.col(static_cast<Eigen::Index>(i)) = center_of(keys[i]).cast<float>();
  return centres_W;
}

void VoxelMap::set_voxels(const std::vector<Voxel>& voxels) {
  for (const Voxel& v : voxels)
    if (!std::isfinite(v.time_s))
      throw std::invalid_argument("voxel time_s = " + std::to_string(v.time_s) + " is not finite");
  auto accessor = impl_->grid->getAccessor();
  const bool indexed = impl_->uses_expiry_index();
  for (const Voxel& v : voxels) {
    const Coord key(v.key.x, v.key.y, v.key.z);
    accessor.setValueOn(key, v.time_s);
    impl_->latest_time_s = std::max(impl_->latest_time_s, v.time_s);
    if (indexed) impl_->schedule(leaf_origin(key), v.time_s + impl_->config.voxel_decay_s);
  }
}

std::size_t VoxelMap::erase(const std::vector<VoxelKey>& keys, std::vector<VoxelKey>* erased) {
  auto accessor = impl_->grid->getAccessor();
  std::size_t removed = 0;
  for (const VoxelKey& k : keys) {
    const Coord key(k.x, k.y, k.z);
    if (!accessor.isValueOn(key)) continue;
    accessor.setValueOff(key);  // a stale expiry-index entry for its leaf finds nothing to expire: harmless
    ++removed;
    if (erased) erased->push_back(k);
  }
  return removed;
}

Costmap2D VoxelMap::project_costmap(const CostmapOptions& options) const {
  const double resolution_m = options.resolution_m == 0.0 ? impl_->config.voxel_size_m : options.resolution_m;
  if (!std::isfinite(resolution_m) || resolution_m <= 0.0)
    throw std::invalid_argument("costmap resolution = " + std::to_string(options.resolution_m) + " must be > 0");
  if (std::isnan(options.min_obstacle_height_m) || std::isnan(options.max_obstacle_height_m) ||
      options.min_obstacle_height_m > options.max_obstacle_height_m)
    throw std::invalid_argument("costmap min_obstacle_height = " + std::to_string(options.min_obstacle_height_m) +
                                " must be <= max_obstacle_height = " + std::to_string(options.max_obstacle_height_m));
  struct Column {
    Eigen::Vector2d centre_W;
    int voxels;
  };
  std::vector<Column> columns_W;  // each column's centre with its voxels inside the band
  const double s = impl_->config.voxel_size_m;
  for_each_column(options.min_obstacle_height_m, options.max_obstacle_height_m, [&](int x, int y, int voxels) {
    columns_W.push_back({Eigen::Vector2d(x + 0.5, y + 0.5) * s, voxels});
  });
  Costmap2D map;
  map.resolution_m = resolution_m;
  if (options.bounds_W) {
    const Eigen::AlignedBox2d& bounds_W = *options.bounds_W;
    if (!bounds_W.min().allFinite() || !bounds_W.max().allFinite() ||
        (bounds_W.max() - bounds_W.min()).minCoeff() < 0.0)
      throw std::invalid_argument("costmap bounds_W must be finite with min <= max");
    map.origin_m = bounds_W.min();
    const Eigen::Vector2d size_m = bounds_W.max() - bounds_W.min();
    const double width_cells = std::max(1.0, std::ceil(size_m.x() / resolution_m - 1e-9));
    const double height_cells = std::max(1.0, std::ceil(size_m.y() / resolution_m - 1e-9));
    if (!(width_cells * height_cells <= 1e8))
      throw std::invalid_argument("costmap of " + std::to_string(width_cells) + " x " + std::to_string(height_cells) +
                                  " cells is too large");
    map.width = static_cast<int>(width_cells);
    map.height = static_cast<int>(height_cells);
  } else if (columns_W.empty()) {
    map.width = map.height = 1;
  } else {
    Eigen::AlignedBox2d extent_W;
    for (const auto& column : columns_W) extent_W.extend(column.centre_W);
    const Eigen::Vector2d lo_cells = (extent_W.min() / resolution_m).array().floor();
    const Eigen::Vector2d hi_cells = (extent_W.max() / resolution_m).array().floor();
    const Eigen::Vector2d cells = (hi_cells - lo_cells).array() + 1.0;
    if (!(cells.prod() <= 1e8))
      throw std::invalid_argument("costmap over the map's extent is too large; give bounds_W");
    map.origin_m = lo_cells * resolution_m;
    map.width = static_cast<int>(cells.x());
    map.height = static_cast<int>(cells.y());
  }
  std::vector<int> counts(static_cast<std::size_t>(map.width) * map.height, 0);
  for (const auto& [column_W, voxels] : columns_W) {
    const double ix = std::floor((column_W.x() - map.origin_m.x()) / resolution_m);
    const double iy = std::floor((column_W.y() - map.origin_m.y()) / resolution_m);
    if (ix < 0 || iy < 0 || ix >= map.width || iy >= map.height) continue;
    counts[static_cast<std::size_t>(iy) * map.width + static_cast<std::size_t>(ix)] += voxels;
  }
  const int threshold = std::max(impl_->config.mark_threshold, 1);
  map.cells.resize(counts.size());
  for (std::size_t i = 0; i < counts.size(); ++i) map.cells[i] = counts[i] >= threshold ? kCostLethal : kCostFree;
  clear_footprint(map, options.free_polygon_W);
  return map;
}

}  // namespace stvl::mapping
