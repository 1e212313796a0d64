#include "recording/recording.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "recording/detail.hpp"

namespace stvl::recording {

const char* to_string(PoseSource source) {
  switch (source) {
    case PoseSource::kTf: return "tf";
    case PoseSource::kOdometry: return "odometry";
    case PoseSource::kFile: return "file";
    case PoseSource::kStatic: return "static";
  }
  return "?";
}

namespace {

enum class Kind { kRos1, kRos2, kPngFolder };

// What `path` holds, by content; throws std::invalid_argument for anything that is not a recording.
Kind kind_of(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    bool rosbag2 = fs::exists(fs::path(path) / "metadata.yaml", ec);
    for (const auto& e : fs::directory_iterator(path, ec))
      rosbag2 = rosbag2 || e.path().extension() == ".mcap" || e.path().extension() == ".db3";
    return rosbag2 ? Kind::kRos2 : Kind::kPngFolder;
  }
  if (!fs::exists(path, ec)) throw std::invalid_argument(path + ": no such file or folder");
  std::ifstream in(path, std::ios::binary);
  char magic[16] = {};
  in.read(magic, 16);
  const std::string head(magic, static_cast<std::size_t>(in.gcount()));
  if (head.compare(0, 13, "#ROSBAG V2.0\n") == 0) return Kind::kRos1;
  if (head.compare(0, 5, "\x89MCAP") == 0 || head.compare(0, 15, "SQLite format 3") == 0) return Kind::kRos2;
  throw std::invalid_argument(
      path +
      ": not a recording: neither a ROS 1 bag ('#ROSBAG V2.0'), an MCAP file (bad magic: "
      "no \\x89MCAP0\\r\\n), a rosbag2 sqlite3 file, nor a folder of depth PNGs or rosbag2 files");
}

}  // namespace

std::unique_ptr<Recording> open_recording(const std::string& path, const RecordingOptions& options) {
  switch (kind_of(path)) {
    case Kind::kRos1: return detail::open_bag(path, options);
    case Kind::kRos2: return detail::open_ros2(path, options);
    case Kind::kPngFolder: break;
  }
  return detail::open_png_folder(path, options);
}

RecordingContents list_recording(const std::string& path) {
  switch (kind_of(path)) {
    case Kind::kRos1: return detail::list_bag(path);
    case Kind::kRos2: return detail::list_ros2(path);
    case Kind::kPngFolder: break;
  }
  const auto recording = detail::open_png_folder(path, RecordingOptions{});
  return RecordingContents{path, recording->info().format, {path}, {}, {}};
}

namespace detail {

std::string nearest_name(const std::string& name, const std::vector<std::string>& candidates) {
  std::string best;
  std::size_t best_distance = std::string::npos;
  for (const auto& c : candidates) {
    std::vector<std::size_t> row(c.size() + 1);
    for (std::size_t j = 0; j <= c.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= name.size(); ++i) {
      std::size_t diagonal = row[0];
      row[0] = i;
      for (std::size_t j = 1; j <= c.size(); ++j) {
        const std::size_t up = row[j];
        row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (name[i - 1] == c[j - 1] ? 0 : 1)});
        diagonal = up;
      }
    }
    if (row[c.size()] < best_distance) best_distance = row[c.size()], best = c;
  }
  return best;
}

Eigen::Isometry3d rigid_from_matrix(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const std::string& what) {
  if (!R.allFinite() || !t.allFinite()) throw std::invalid_argument(what + ": transform is not finite");
  const double error = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (error > 1e-3 || R.determinant() < 0) {
    throw std::invalid_argument(what + ": not a rigid transform (rotation not orthonormal: |R^T R - I| = " +
                                std::to_string(error) + ", det " + std::to_string(R.determinant()) + ")");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  T.translation() = t;
  return T;
}

Eigen::Isometry3d rigid_from_quaternion(double tx, double ty, double tz, double qx, double qy, double qz, double qw,
                                        const std::string& what) {
  const Eigen::Quaterniond q(qw, qx, qy, qz);
  if (!q.coeffs().allFinite()) throw std::invalid_argument(what + ": rotation is not finite");
  // The matrix of a non-unit quaternion is scaled by its squared norm: not orthonormal.
  if (std::abs(q.squaredNorm() - 1.0) > 1e-3) {
    throw std::invalid_argument(what + ": not a rigid transform (quaternion norm " + std::to_string(q.norm()) +
                                ", expected 1)");
  }
  return rigid_from_matrix(q.normalized().toRotationMatrix(), Eigen::Vector3d(tx, ty, tz), what);
}

sensors::CameraIntrinsics make_intrinsics(double width, double height, double fx, double fy, double cx, double cy,
                                          double rate_hz, const RecordingOptions& options, const std::string& what) {
  auto require = [&](bool ok, const char* field, double value) {
    if (!ok) throw std::invalid_argument(what + ": bad intrinsics: " + field + " = " + std::to_string(value));
  };
  require(std::isfinite(width) && width >= 1 && width <= 65535 && width == std::floor(width), "width", width);
  require(std::isfinite(height) && height >= 1 && height <= 65535 && height == std::floor(height), "height", height);
  require(std::isfinite(fx) && fx > 0, "fx", fx);
  require(std::isfinite(fy) && fy > 0, "fy", fy);
  require(std::isfinite(cx), "cx", cx);
  require(std::isfinite(cy), "cy", cy);
  sensors::CameraIntrinsics k;
  k.width = static_cast<int>(width), k.height = static_cast<int>(height);
  k.fx = fx, k.fy = fy, k.cx = cx, k.cy = cy;
  k.min_range_m = options.min_range_m, k.max_range_m = options.max_range_m;
  k.rate_hz = rate_hz;
  try {
    k.validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(what + ": bad intrinsics: " + e.what());
  }
  return k;
}

}  // namespace detail
}  // namespace stvl::recording
