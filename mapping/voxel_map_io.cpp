// VoxelMap's files: .vdb (one DoubleGrid plus the config as metadata) and binary PLY.
#include <openvdb/io/File.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/atomic_file.hpp"
#include "mapping/detail/voxel_map_impl.hpp"

namespace stvl::mapping {

using detail::GridT;
using detail::kGridName;

void VoxelMap::save_vdb(const std::string& path) const {
  const StvlConfig& c = impl_->config;
  GridT::Ptr out = impl_->grid->copy();  // shares the tree; metadata is the copy's own
  out->setName(kGridName);
  out->insertMeta("voxel_size", openvdb::DoubleMetadata(c.voxel_size_m));
  out->insertMeta("voxel_decay", openvdb::DoubleMetadata(c.voxel_decay_s));
  out->insertMeta("decay_model", openvdb::StringMetadata(to_string(c.decay_model)));
  out->insertMeta("mark_threshold", openvdb::Int32Metadata(c.mark_threshold));
  out->insertMeta("clearing_mode", openvdb::StringMetadata(to_string(c.clearing_mode)));
  out->insertMeta("clearing_walk", openvdb::StringMetadata(to_string(c.clearing_walk)));
  out->insertMeta("mark_rounding", openvdb::StringMetadata(to_string(c.mark_rounding)));
  out->insertMeta("frustum_geometry", openvdb::StringMetadata(to_string(c.frustum_geometry)));
  out->insertMeta("expiry_leaves_per_update",
                  openvdb::Int64Metadata(static_cast<openvdb::Int64>(c.expiry_leaves_per_update)));
  out->insertMeta("latest_time_s", openvdb::DoubleMetadata(impl_->latest_time_s));
  write_via_temporary(path, [&](const std::filesystem::path& temp) {
    try {
      openvdb::io::File file(temp.string());
      file.write(openvdb::GridCPtrVec{out});
      file.close();
    } catch (const openvdb::Exception& e) {
      throw std::runtime_error("cannot write '" + path + "': " + e.what());
    }
  });
}

VoxelMap VoxelMap::load_vdb(const std::string& path) {
  detail::ensure_openvdb_initialized();
  GridT::Ptr grid;
  try {
    openvdb::io::File file(path);
    file.open();
    if (!file.hasGrid(kGridName)) throw std::runtime_error("'" + path + "' holds no grid named " + kGridName);
    grid = openvdb::gridPtrCast<GridT>(file.readGrid(kGridName));
    file.close();
  } catch (const openvdb::Exception& e) {
    throw std::runtime_error("cannot read '" + path + "': " + e.what());
  }
  if (!grid) throw std::runtime_error("'" + path + "': grid " + kGridName + " is not a DoubleGrid");
  StvlConfig config;
  try {
    auto meta_double = [&](const char* name, double fallback) {
      auto m = grid->getMetadata<openvdb::DoubleMetadata>(name);
      return m ? m->value() : fallback;
    };
    auto meta_string = [&](const char* name, const std::string& fallback) {
      auto m = grid->getMetadata<openvdb::StringMetadata>(name);
      return m ? m->value() : fallback;
    };
    if (!grid->getMetadata<openvdb::DoubleMetadata>("voxel_size"))
      throw std::invalid_argument("voxel_size metadata missing");
    config.voxel_size_m = meta_double("voxel_size", config.voxel_size_m);
    config.voxel_decay_s = meta_double("voxel_decay", config.voxel_decay_s);
    config.decay_model = parse_decay_model(meta_string("decay_model", to_string(config.decay_model)));
    if (auto m = grid->getMetadata<openvdb::Int32Metadata>("mark_threshold")) config.mark_threshold = m->value();
    config.clearing_mode = parse_clearing_mode(meta_string("clearing_mode", to_string(config.clearing_mode)));
    config.clearing_walk = parse_clearing_walk(meta_string("clearing_walk", to_string(config.clearing_walk)));
    config.mark_rounding = parse_mark_rounding(meta_string("mark_rounding", to_string(config.mark_rounding)));
    config.frustum_geometry =
        parse_frustum_geometry(meta_string("frustum_geometry", to_string(config.frustum_geometry)));
    if (auto m = grid->getMetadata<openvdb::Int64Metadata>("expiry_leaves_per_update"))
      config.expiry_leaves_per_update = static_cast<std::size_t>(std::max<openvdb::Int64>(m->value(), 0));
    config.validate();
    const double transform_voxel_size_m = grid->voxelSize().x();
    if (std::abs(transform_voxel_size_m - config.voxel_size_m) > 1e-9 * config.voxel_size_m)
      throw std::invalid_argument("transform voxel size " + std::to_string(transform_voxel_size_m) +
                                  " differs from voxel_size metadata " + std::to_string(config.voxel_size_m));
    VoxelMap map(config);
    map.impl_->latest_time_s = meta_double("latest_time_s", -std::numeric_limits<double>::infinity());
    for (auto it = grid->cbeginValueOn(); it; ++it)
      if (!std::isfinite(*it)) throw std::invalid_argument("voxel holds a non-finite time");
    map.impl_->grid = grid;
    map.impl_->grid->tree().clearAllAccessors();
    map.impl_->rebuild_expiry_index();
    return map;
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error("'" + path + "' is not a valid stvl map: " + e.what());
  }
}

void VoxelMap::save_ply(const std::string& path) const {
  const std::vector<Voxel> all = voxels();
  std::string bytes = "ply\nformat binary_little_endian 1.0\nelement vertex " + std::to_string(all.size()) +
                      "\nproperty float x\nproperty float y\nproperty float z\nproperty double time\nend_header\n";
  const std::uint16_t probe = 1;
  const bool little_endian = *reinterpret_cast<const std::uint8_t*>(&probe) == 1;
  auto append = [&](const void* data, std::size_t n) {
    const char* p = static_cast<const char*>(data);
    if (little_endian) {
      bytes.append(p, n);
    } else {
      for (std::size_t i = n; i-- > 0;) bytes.push_back(p[i]);
    }
  };
  for (const Voxel& v : all) {
    const Eigen::Vector3f centre_W = center_of(v.key).cast<float>();
    for (int a = 0; a < 3; ++a) append(&centre_W[a], sizeof(float));
    append(&v.time_s, sizeof(double));
  }
  write_file_atomically(path, bytes);
}

}  // namespace stvl::mapping
