#pragma once
// The plain twin of evaluation/observe_keys.hpp: one pixel after another, then sorted and unique.
#include "evaluation/observe_keys.hpp"

namespace stvl::evaluation::reference {

void observed_keys(const sensors::DepthImage& clean_depth, const sensors::CameraIntrinsics& intrinsics,
                   const Eigen::Isometry3d& T_world_camera, double obstacle_range_m, const EvaluationConfig& config,
                   std::vector<VoxelKey>& keys);

}  // namespace stvl::evaluation::reference
