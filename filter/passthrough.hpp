#pragma once
#include <Eigen/Core>

#include <limits>

namespace stvl::filter {

// Keeps points with min_z_m <= z <= max_z_m (world frame), as STVL does before marking. Non-finite points
// are dropped. min_z_m > max_z_m or a NaN bound throws std::invalid_argument.
struct PassthroughConfig {
  double min_z_m = -std::numeric_limits<double>::infinity();
  double max_z_m = std::numeric_limits<double>::infinity();
};

Eigen::Matrix3Xf passthrough(const Eigen::Matrix3Xf& points_W, const PassthroughConfig& config);

}  // namespace stvl::filter
