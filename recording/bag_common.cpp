#include "recording/bag_common.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "recording/detail.hpp"

namespace stvl::recording::detail {

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

std::string strip_slash(std::string frame) {
  if (!frame.empty() && frame.front() == '/') frame.erase(0, 1);
  return frame;
}

int depth_bytes_per_pixel(const std::string& encoding, const std::string& where) {
  if (encoding == "16UC1" || encoding == "mono16") return 2;
  if (encoding == "32FC1") return 4;
  throw std::invalid_argument(where + ": encoding '" + encoding + "' is not depth (expected 16UC1, mono16 or 32FC1)");
}

void decode_depth(const ImageView& image, const sensors::CameraIntrinsics& k, double unit_m, const std::string& at,
                  const std::string& info_topic, sensors::DepthImage& out) {
  const int bpp = depth_bytes_per_pixel(image.encoding, at);
  if (image.width == 0 || image.height == 0) {
    throw std::invalid_argument(at + ": empty image (" + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + ")");
  }
  if (int(image.width) != k.width || int(image.height) != k.height) {
    throw std::invalid_argument(at + ": image is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                                " but " + info_topic + " says " + std::to_string(k.width) + "x" +
                                std::to_string(k.height));
  }
  const std::size_t row_bytes = std::size_t(image.width) * bpp;
  if (image.step < row_bytes) {
    throw std::invalid_argument(at + ": step " + std::to_string(image.step) + " < width x " + std::to_string(bpp) +
                                " bytes = " + std::to_string(row_bytes));
  }
  if (image.size < std::size_t(image.step) * image.height) {
    throw std::invalid_argument(at + ": data has " + std::to_string(image.size) +
                                " bytes < step x height = " + std::to_string(std::size_t(image.step) * image.height));
  }
  const bool swap = image.is_bigendian != (__BYTE_ORDER__ == __ORDER_BIG_ENDIAN__);
  out.width = k.width, out.height = k.height;
  out.depth_m.resize(std::size_t(k.width) * k.height);
  const float unit = static_cast<float>(unit_m);
  for (int v = 0; v < k.height; ++v) {
    const std::uint8_t* row = image.data + std::size_t(v) * image.step;
    float* dst = out.depth_m.data() + std::size_t(v) * k.width;
    for (int u = 0; u < k.width; ++u) {
      std::uint8_t b[4];
      std::memcpy(b, row + std::size_t(u) * bpp, bpp);
      if (swap) std::reverse(b, b + bpp);
      if (bpp == 2) {
        std::uint16_t d;
        std::memcpy(&d, b, 2);
        dst[u] = d * unit;
      } else {
        float d;
        std::memcpy(&d, b, 4);
        dst[u] = std::isfinite(d) && d > 0 ? d : 0.0f;
      }
    }
  }
}

void PoseResolver::add_transform(const std::string& path, const std::string& topic, bool is_static,
                                 const std::string& parent_id, const std::string& child_id, double stamp_s,
                                 const double t[3], const double q[4]) {
  const std::string parent = strip_slash(parent_id), child = strip_slash(child_id);
  const Eigen::Isometry3d T = rigid_from_quaternion(
      t[0], t[1], t[2], q[0], q[1], q[2], q[3],
      path + ": " + topic + " " + parent + " -> " + child + " at t = " + std::to_string(stamp_s) + " s");
  auto& edge = tf_.edges[child];
  if (!edge.parent.empty() && edge.parent != parent) {
    throw std::invalid_argument(path + ": " + topic + ": frame '" + child + "' has two parents ('" + edge.parent +
                                "' and '" + parent + "')");
  }
  edge.parent = parent;
  if (is_static) {
    edge.is_static = true, edge.T_static = T;
  } else if (!edge.is_static) {
    edge.series.samples.emplace_back(stamp_s, T);
  }
}

void PoseResolver::add_odometry(const std::string& path, const std::string& topic, double stamp_s,
                                const std::string& frame, const std::string& child, const double p[3],
                                const double q[4]) {
  if (odom_.samples.empty()) odom_frame_ = strip_slash(frame), base_frame_ = strip_slash(child);
  odom_.samples.emplace_back(
      stamp_s, rigid_from_quaternion(p[0], p[1], p[2], q[0], q[1], q[2], q[3],
                                     path + ": " + topic + " pose at t = " + std::to_string(stamp_s) + " s"));
}

void PoseResolver::resolve(RecordingInfo& info, const RecordingOptions& options) {
  for (auto& [child, edge] : tf_.edges) edge.series.sort();
  const std::string& camera = info.camera_frame;
  const std::string& path = info.path;
  if (!options.odom_topic.empty()) {
    if (odom_.samples.empty()) throw std::invalid_argument(path + ": " + options.odom_topic + " has no messages");
    odom_.sort();
    info.fixed_frame = odom_frame_;
    if (!options.fixed_frame.empty() && options.fixed_frame != info.fixed_frame) {
      throw std::invalid_argument(path + ": fixed frame '" + options.fixed_frame + "' but " + options.odom_topic +
                                  " gives poses in '" + info.fixed_frame + "'");
    }
    T_base_camera_ = options.T_base_camera;
    bool all_static = true;
    for (const auto& f : tf_.chain(camera)) {
      if (f == base_frame_) break;
      const auto e = tf_.edges.find(f);
      all_static = all_static && e != tf_.edges.end() && e->second.is_static;
    }
    if (!base_frame_.empty() && tf_.links(base_frame_, camera) && all_static)
      T_base_camera_ = tf_.lookup(base_frame_, camera, 0.0);
    info.pose_source = PoseSource::kOdometry;
    return;
  }
  if (tf_.has(camera)) {
    info.fixed_frame = options.fixed_frame.empty() ? tf_.root_of(camera) : options.fixed_frame;
    if (!tf_.links(info.fixed_frame, camera)) {
      throw std::invalid_argument(path + ": fixed frame '" + info.fixed_frame + "' is not above '" + camera +
                                  "' in /tf (its chain: " + join(tf_.chain(camera)) + ")");
    }
    const auto chain = tf_.chain(camera);
    for (const char* base : {"base_link", "base_footprint"}) {
      if (std::find(chain.begin(), chain.end(), base) != chain.end() && tf_.links(info.fixed_frame, base)) {
        base_frame_ = base;
        break;
      }
    }
    info.pose_source = PoseSource::kTf;
    return;
  }
  // The camera is not in /tf but the robot is: base_link from /tf, the camera on it from the options.
  for (const char* base : {"base_link", "base_footprint"}) {
    if (!tf_.edges.count(base)) continue;
    info.fixed_frame = options.fixed_frame.empty() ? tf_.root_of(base) : options.fixed_frame;
    if (!tf_.links(info.fixed_frame, base)) {
      throw std::invalid_argument(path + ": fixed frame '" + info.fixed_frame + "' is not above '" + base +
                                  "' in /tf (its chain: " + join(tf_.chain(base)) + ")");
    }
    base_frame_ = base;
    camera_from_options_ = true;
    info.pose_source = PoseSource::kTf;
    return;
  }
  if (!options.fixed_frame.empty()) {
    throw std::invalid_argument(path + ": fixed frame '" + options.fixed_frame + "' asked for, but the bag's " +
                                "/tf has no frame '" + camera + "' (the images' frame_id)");
  }
  info.fixed_frame = "world";
  info.pose_source = PoseSource::kStatic;
}

void PoseResolver::pose_at(const RecordingInfo& info, const RecordingOptions& options, const std::string& where,
                           double t, std::size_t index, Eigen::Isometry3d& T_fixed_camera,
                           Eigen::Isometry3d& T_fixed_base) const {
  try {
    switch (info.pose_source) {
      case PoseSource::kTf:
        if (camera_from_options_) {
          T_fixed_base = tf_.lookup(info.fixed_frame, base_frame_, t);
          T_fixed_camera = T_fixed_base * options.T_base_camera;
          return;
        }
        T_fixed_camera = tf_.lookup(info.fixed_frame, info.camera_frame, t);
        T_fixed_base = base_frame_.empty() ? T_fixed_camera * options.T_base_camera.inverse()
                                           : tf_.lookup(info.fixed_frame, base_frame_, t);
        return;
      case PoseSource::kOdometry: {
        const auto T = odom_.at(t);
        if (!T) {
          throw std::invalid_argument("no pose at t = " + std::to_string(t) + " s: " + options.odom_topic +
                                      " covers only " + odom_.span() + " (no extrapolation)");
        }
        T_fixed_base = *T;
        T_fixed_camera = T_fixed_base * T_base_camera_;
        return;
      }
      default: T_fixed_base = options.T_fixed_base; T_fixed_camera = options.T_fixed_base * options.T_base_camera;
    }
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(where + ": frame " + std::to_string(index) + " (frame_id '" + info.camera_frame +
                                "'): " + e.what());
  }
}

}  // namespace stvl::recording::detail
