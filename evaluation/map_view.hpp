#pragma once
// The final map for the report's 3D view, world frame: mapped voxel centres within the evaluation's tolerance of
// the truth, the other mapped ones, and the truth's voxel centres; each thinned to about max_points (chosen by a
// hash of the voxel key, so the view is spread evenly and deterministic). Without ground truth (a replayed
// recording) every mapped voxel is unjudged.
#include <cstddef>

#include <Eigen/Core>

#include "evaluation/truth.hpp"
#include "mapping/voxel_map.hpp"

namespace stvl::evaluation {

struct MapView {
  double voxel_size_m = 0;
  Eigen::Matrix3Xf mapped_true_W, mapped_false_W, truth_W, unjudged_W;
  std::size_t mapped_true = 0, mapped_false = 0, truth = 0, unjudged = 0;  // before thinning
};

// The map judged against the truth: a mapped voxel is true within tolerance_voxels of a truth voxel.
MapView make_map_view(const mapping::VoxelMap& map, const Truth& truth, int tolerance_voxels,
                      std::size_t max_points = 60000);
// The map alone, every voxel unjudged.
MapView make_map_view(const mapping::VoxelMap& map, std::size_t max_points = 60000);

}  // namespace stvl::evaluation
