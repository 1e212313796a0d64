#pragma once
// PCL's VoxelGrid as the filter benchmark's peer, built only when libpcl-dev is installed (STVL_HAVE_PCL).
#include <Eigen/Core>

#include <string>
#include <vector>

#include "bench/filter_bench.hpp"

namespace stvl::bench {

bool pcl_peer_available();
// Rows "pcl2/cpu" (VoxelGrid<PCLPointCloud2> with z limits, the call STVL makes) and "pclxyz/cpu"
// (VoxelGrid<PointXYZ>) for each cloud and voxel size. Throws std::runtime_error when built without PCL.
std::vector<FilterBenchRow> run_pcl_peer(const std::vector<BenchmarkCloud>& clouds,
                                         const std::vector<double>& voxel_sizes_m, int warmup, int repetitions);

}  // namespace stvl::bench
