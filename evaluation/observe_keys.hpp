#pragma once
// The voxels a camera sees in its noise-free depth, for recall: every kObserveStride-th pixel of every
// kObserveStride-th row with a return, within the source's obstacle range of the optical centre, placed in the world
// in float (as the camera's cloud is) and kept inside the evaluation's height band. The plain per-pixel loop it
// must equal is reference/observe_keys.hpp (tests compare them).
#include <vector>

#include <Eigen/Geometry>

#include "common/voxel_key.hpp"
#include "evaluation/config.hpp"
#include "sensors/camera.hpp"
#include "sensors/depth_image.hpp"

namespace stvl::evaluation {

constexpr int kObserveStride = 2;  // every second pixel of every second row

// The keys, sorted and unique, into `keys` (row blocks in parallel, each row's keys computed branch-free with
// AVX2 where the CPU has it, then a voxel equal to its left or upper neighbour's skipped before sorting).
void observed_keys(const sensors::DepthImage& clean_depth, const sensors::CameraIntrinsics& intrinsics,
                   const Eigen::Isometry3d& T_world_camera, double obstacle_range_m, const EvaluationConfig& config,
                   std::vector<VoxelKey>& keys);

}  // namespace stvl::evaluation
