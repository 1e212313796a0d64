#include "bench/pcl_peer.hpp"

#include <stdexcept>

#include "bench/timing.hpp"

#ifdef STVL_HAVE_PCL
#include <pcl/conversions.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_types.h>
#endif

namespace stvl::bench {

#ifdef STVL_HAVE_PCL
bool pcl_peer_available() { return true; }

std::vector<FilterBenchRow> run_pcl_peer(const std::vector<BenchmarkCloud>& clouds,
                                         const std::vector<double>& voxel_sizes_m, int warmup, int repetitions) {
  std::vector<FilterBenchRow> rows;
  for (const auto& cloud : clouds) {
    pcl::PointCloud<pcl::PointXYZ>::Ptr xyz(new pcl::PointCloud<pcl::PointXYZ>);
    xyz->resize(static_cast<std::size_t>(cloud.points.cols()));
    for (Eigen::Index i = 0; i < cloud.points.cols(); ++i)
      (*xyz)[static_cast<std::size_t>(i)] = pcl::PointXYZ(cloud.points(0, i), cloud.points(1, i), cloud.points(2, i));
    pcl::PCLPointCloud2::Ptr blob(new pcl::PCLPointCloud2);
    pcl::toPCLPointCloud2(*xyz, *blob);
    const float z_min = cloud.points.row(2).minCoeff() - 1.0f, z_max = cloud.points.row(2).maxCoeff() + 1.0f;
    for (double voxel : voxel_sizes_m) {
      const float leaf = static_cast<float>(voxel);
      pcl::PCLPointCloud2 out2;
      pcl::VoxelGrid<pcl::PCLPointCloud2> grid2;
      grid2.setInputCloud(blob);
      grid2.setLeafSize(leaf, leaf, leaf);
      grid2.setFilterFieldName("z");
      grid2.setFilterLimits(z_min, z_max);
      const auto [mean2, std2] = time_ms([&] { grid2.filter(out2); }, warmup, repetitions);
      rows.push_back({cloud.name, "pcl2/cpu", voxel, static_cast<std::size_t>(cloud.points.cols()),
                      static_cast<std::size_t>(out2.width) * out2.height, mean2, std2});
      pcl::PointCloud<pcl::PointXYZ> out;
      pcl::VoxelGrid<pcl::PointXYZ> grid;
      grid.setInputCloud(xyz);
      grid.setLeafSize(leaf, leaf, leaf);
      const auto [mean, std] = time_ms([&] { grid.filter(out); }, warmup, repetitions);
      rows.push_back(
          {cloud.name, "pclxyz/cpu", voxel, static_cast<std::size_t>(cloud.points.cols()), out.size(), mean, std});
    }
  }
  return rows;
}
#else
bool pcl_peer_available() { return false; }

std::vector<FilterBenchRow> run_pcl_peer(const std::vector<BenchmarkCloud>&, const std::vector<double>&, int, int) {
  throw std::runtime_error(
      "--peer pcl: stvl-bench was built without PCL (install libpcl-dev with "
      "scripts/install-deps.sh --with-pcl and rebuild)");
}
#endif

}  // namespace stvl::bench
