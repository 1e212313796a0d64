// Folders of 16-bit depth PNGs: DIR/*.png or DIR/depth/*.png, intrinsics from DIR/intrinsics.yaml or per-frame
// OpenCV calibrations DIR/calib/<name>.yaml, optional DIR/poses.txt (TUM) and DIR/timestamps.txt.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

#include "common/png.hpp"
#include "recording/detail.hpp"

namespace stvl::recording::detail {
namespace {

namespace fs = std::filesystem;

struct PngHeader {
  int width = 0, height = 0, bit_depth = 0, color_type = -1;
};

// Reads the IHDR chunk only; empty when the file is not a PNG.
std::optional<PngHeader> read_png_header(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  unsigned char b[26] = {};
  in.read(reinterpret_cast<char*>(b), sizeof b);
  static const unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (!in || !std::equal(kSignature, kSignature + 8, b) || std::string(reinterpret_cast<char*>(b + 12), 4) != "IHDR") {
    return std::nullopt;
  }
  auto be32 = [&](int i) { return int(b[i]) << 24 | int(b[i + 1]) << 16 | int(b[i + 2]) << 8 | int(b[i + 3]); };
  return PngHeader{be32(16), be32(20), b[24], b[25]};
}

// Numeric names in numeric order (2 < 10 < 154), others after them by name.
bool name_less(const fs::path& a, const fs::path& b) {
  const std::string sa = a.stem().string(), sb = b.stem().string();
  auto numeric = [](const std::string& s) {
    return !s.empty() && s.size() < 19 &&
           std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c); });
  };
  const bool na = numeric(sa), nb = numeric(sb);
  if (na != nb) return na;
  if (na && std::stoll(sa) != std::stoll(sb)) return std::stoll(sa) < std::stoll(sb);
  return sa < sb;
}

YAML::Node load_yaml(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path.string() + ": cannot read");
  std::stringstream text;
  std::string line;
  bool first = true;
  int skipped = 0;
  while (std::getline(in, line)) {
    // OpenCV writes "%YAML:1.0", a directive yaml-cpp rejects; keep the line count for error lines.
    if (first && line.rfind("%YAML:", 0) == 0) line = "", ++skipped;
    first = false;
    text << line << '\n';
  }
  try {
    return YAML::Load(text.str());
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(path.string() + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
}

double number(const YAML::Node& map, const std::string& key, const fs::path& file,
              std::optional<double> fallback = {}) {
  const YAML::Node node = map[key];
  if (!node) {
    if (fallback) return *fallback;
    throw std::invalid_argument(file.string() + ": " + key + ": required key is missing");
  }
  try {
    return node.as<double>();
  } catch (const YAML::Exception&) {
    throw std::invalid_argument(file.string() + ":" + std::to_string(node.Mark().line + 1) + ": " + key +
                                ": expected a number");
  }
}

std::vector<double> matrix_data(const YAML::Node& map, const std::string& key, std::size_t count,
                                const fs::path& file) {
  const YAML::Node data = map[key] ? map[key]["data"] : YAML::Node();
  if (!data || !data.IsSequence() || data.size() != count) {
    throw std::invalid_argument(file.string() + ": " + key + ".data: expected " + std::to_string(count) + " numbers");
  }
  std::vector<double> out;
  for (const auto& v : data) {
    try {
      out.push_back(v.as<double>());
    } catch (const YAML::Exception&) {
      throw std::invalid_argument(file.string() + ":" + std::to_string(v.Mark().line + 1) + ": " + key +
                                  ".data: expected numbers");
    }
  }
  return out;
}

struct FrameCalibration {
  sensors::CameraIntrinsics intrinsics;
  Eigen::Isometry3d T_base_camera = Eigen::Isometry3d::Identity();
};

class PngFolderRecording final : public Recording {
 public:
  PngFolderRecording(const std::string& path, const RecordingOptions& options) : options_(options) {
    const fs::path dir(path);
    info_.path = path;
    info_.files = {path};
    info_.format = "png folder";
    info_.encoding = "png16";
    info_.camera_frame = "camera";
    info_.fixed_frame = options.fixed_frame.empty() ? "world" : options.fixed_frame;
    list_depth_pngs(dir);
    read_folder_intrinsics(dir, path);
    check_pngs();
    // Times and poses.
    const double rate_hz = info_.intrinsics.rate_hz;
    for (std::size_t i = 0; i < files_.size(); ++i) stamps_.push_back(double(i) / rate_hz);
    if (fs::exists(dir / "poses.txt")) read_poses(dir / "poses.txt");
    if (fs::exists(dir / "timestamps.txt")) read_timestamps(dir / "timestamps.txt");
    info_.start_time_s = stamps_.front();
    info_.end_time_s = stamps_.back();
  }

  const RecordingInfo& info() const override { return info_; }

  bool next(RecordedFrame& frame) override {
    if (index_ >= files_.size()) return false;
    const FrameCalibration& c = calibration(index_);
    Gray16Image png;
    try {
      png = read_png_gray16(files_[index_]);
    } catch (const std::exception& e) {
      throw std::invalid_argument(files_[index_].string() + ": cannot read the depth PNG: " + e.what());
    }
    if (png.width != c.intrinsics.width || png.height != c.intrinsics.height) {
      throw std::invalid_argument(files_[index_].string() + ": size differs from the intrinsics");
    }
    frame.index = index_;
    frame.stamp_s = stamps_[index_];
    frame.time_s = frame.stamp_s - info_.start_time_s;
    frame.intrinsics = c.intrinsics;
    frame.depth.width = png.width, frame.depth.height = png.height;
    frame.depth.depth_m.resize(png.pixels.size());
    for (std::size_t i = 0; i < png.pixels.size(); ++i) frame.depth.depth_m[i] = float(png.pixels[i] * depth_scale_m_);
    if (!poses_.empty()) {
      frame.T_fixed_camera = poses_[index_];
      frame.T_fixed_base = frame.T_fixed_camera * c.T_base_camera.inverse();
    } else {
      frame.T_fixed_base = options_.T_fixed_base;
      frame.T_fixed_camera = options_.T_fixed_base * c.T_base_camera;
    }
    ++index_;
    return true;
  }

 private:
  // The depth PNGs of dir/depth (or dir), in name order; anything else there but the folder's own files throws.
  void list_depth_pngs(const fs::path& dir) {
    const fs::path image_dir = fs::is_directory(dir / "depth") ? dir / "depth" : dir;
    static const std::set<std::string> kKnown = {"intrinsics.yaml", "poses.txt", "timestamps.txt", "README.md"};
    for (const auto& entry : fs::directory_iterator(image_dir)) {
      const std::string name = entry.path().filename().string();
      if (entry.is_directory() || name.front() == '.' || (image_dir == dir && kKnown.count(name))) continue;
      if (entry.path().extension() != ".png") {
        throw std::invalid_argument(image_dir.string() + ": mixed files: '" + name + "' is not a depth PNG");
      }
      files_.push_back(entry.path());
    }
    if (files_.empty()) throw std::invalid_argument(image_dir.string() + ": empty folder: no depth PNGs (*.png)");
    std::sort(files_.begin(), files_.end(), name_less);
    info_.frame_count = files_.size();
  }

  // Intrinsics from intrinsics.yaml (static poses) or calib/<name>.yaml per frame (poses from the files).
  void read_folder_intrinsics(const fs::path& dir, const std::string& path) {
    const bool has_yaml = fs::exists(dir / "intrinsics.yaml"), has_calib = fs::is_directory(dir / "calib");
    if (has_yaml && has_calib) {
      throw std::invalid_argument(path + ": both intrinsics.yaml and calib/ give intrinsics; keep one");
    }
    if (has_yaml) {
      read_intrinsics_yaml(dir / "intrinsics.yaml");
    } else if (has_calib) {
      for (const auto& f : files_) calib_.push_back(read_calib(dir / "calib" / (f.stem().string() + ".yaml")));
    } else {
      throw std::invalid_argument(path + ": missing intrinsics: neither intrinsics.yaml nor calib/<name>.yaml");
    }
    info_.intrinsics = calib_.front().intrinsics;
    info_.pose_source = has_calib ? PoseSource::kFile : PoseSource::kStatic;
  }

  // Every PNG: 16-bit grey, of its intrinsics' size.
  void check_pngs() const {
    for (std::size_t i = 0; i < files_.size(); ++i) {
      const auto header = read_png_header(files_[i]);
      const std::string name = files_[i].string();
      if (!header) throw std::invalid_argument(name + ": mixed files: not a PNG");
      if (header->bit_depth != 16 || header->color_type != 0) {
        throw std::invalid_argument(name + ": mixed files: a " + std::to_string(header->bit_depth) + "-bit " +
                                    (header->color_type == 0 ? "grey" : "colour") + " PNG, expected 16-bit grey depth");
      }
      const auto& k = calibration(i).intrinsics;
      if (header->width != k.width || header->height != k.height) {
        throw std::invalid_argument(name + ": mixed files: " + std::to_string(header->width) + "x" +
                                    std::to_string(header->height) + " but the intrinsics say " +
                                    std::to_string(k.width) + "x" + std::to_string(k.height));
      }
    }
  }

  const FrameCalibration& calibration(std::size_t i) const { return calib_.size() == 1 ? calib_.front() : calib_[i]; }

  void read_intrinsics_yaml(const fs::path& file) {
    const YAML::Node root = load_yaml(file);
    if (!root.IsMap()) throw std::invalid_argument(file.string() + ": expected a mapping of width, height, fx, ...");
    static const std::vector<std::string> kKeys = {"width", "height",        "fx",     "fy", "cx",
                                                   "cy",    "depth_scale_m", "rate_hz"};
    for (const auto& kv : root) {
      const std::string key = kv.first.as<std::string>();
      if (std::find(kKeys.begin(), kKeys.end(), key) == kKeys.end()) {
        throw std::invalid_argument(file.string() + ":" + std::to_string(kv.first.Mark().line + 1) + ": " + key +
                                    ": unknown key (did you mean " + nearest_name(key, kKeys) + "?)");
      }
    }
    depth_scale_m_ = number(root, "depth_scale_m", file, 0.001);
    if (!std::isfinite(depth_scale_m_) || !(depth_scale_m_ > 0)) {
      throw std::invalid_argument(file.string() + ": depth_scale_m must be a positive number of metres");
    }
    const double rate_hz = number(root, "rate_hz", file, options_.rate_hz);
    if (!std::isfinite(rate_hz) || !(rate_hz > 0)) throw std::invalid_argument(file.string() + ": rate_hz must be > 0");
    FrameCalibration c;
    c.intrinsics = make_intrinsics(number(root, "width", file), number(root, "height", file), number(root, "fx", file),
                                   number(root, "fy", file), number(root, "cx", file), number(root, "cy", file),
                                   rate_hz, options_, file.string());
    c.T_base_camera = options_.T_base_camera;
    calib_.push_back(c);
  }

  FrameCalibration read_calib(const fs::path& file) const {
    if (!fs::exists(file)) throw std::invalid_argument(file.string() + ": missing calibration for this frame");
    const YAML::Node root = load_yaml(file);
    const auto K = matrix_data(root, "camera_matrix", 9, file);
    FrameCalibration c;
    c.intrinsics = make_intrinsics(number(root, "image_width", file), number(root, "image_height", file), K[0], K[4],
                                   K[2], K[5], options_.rate_hz, options_, file.string() + ": camera_matrix");
    c.T_base_camera = options_.T_base_camera;
    if (root["local_transform"]) {
      const auto m = matrix_data(root, "local_transform", 12, file);
      Eigen::Matrix3d R;
      R << m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10];
      c.T_base_camera = rigid_from_matrix(R, Eigen::Vector3d(m[3], m[7], m[11]), file.string() + ": local_transform");
    }
    return c;
  }

  void read_poses(const fs::path& file) {
    std::ifstream in(file);
    std::string line;
    int line_number = 0;
    while (std::getline(in, line)) {
      ++line_number;
      const auto first = line.find_first_not_of(" \t\r");
      if (first == std::string::npos || line[first] == '#') continue;
      std::istringstream fields(line);
      double v[8];
      std::string extra;
      for (double& x : v) fields >> x;
      const std::string at = file.string() + ":" + std::to_string(line_number);
      if (fields.fail() || (fields >> extra)) {
        throw std::invalid_argument(at + ": bad pose line, expected 'timestamp tx ty tz qx qy qz qw'");
      }
      if (!std::isfinite(v[0])) throw std::invalid_argument(at + ": timestamp is not finite");
      poses_.push_back(rigid_from_quaternion(v[1], v[2], v[3], v[4], v[5], v[6], v[7], at));
      pose_stamps_.push_back(v[0]);
    }
    if (poses_.size() != files_.size()) {
      throw std::invalid_argument(file.string() + ": " + std::to_string(poses_.size()) + " poses for " +
                                  std::to_string(files_.size()) + " depth PNGs (one per frame, in order)");
    }
    stamps_ = pose_stamps_;
    info_.pose_source = PoseSource::kFile;
  }

  void read_timestamps(const fs::path& file) {
    std::ifstream in(file);
    std::string line;
    int line_number = 0;
    std::vector<double> stamps;
    while (std::getline(in, line)) {
      ++line_number;
      const auto first = line.find_first_not_of(" \t\r");
      if (first == std::string::npos || line[first] == '#') continue;
      std::istringstream fields(line);
      double t;
      if (!(fields >> t) || !std::isfinite(t)) {
        throw std::invalid_argument(file.string() + ":" + std::to_string(line_number) + ": expected a time in seconds");
      }
      stamps.push_back(t);
    }
    if (stamps.size() != files_.size()) {
      throw std::invalid_argument(file.string() + ": " + std::to_string(stamps.size()) + " times for " +
                                  std::to_string(files_.size()) + " depth PNGs");
    }
    stamps_ = stamps;
  }

  RecordingOptions options_;
  RecordingInfo info_;
  std::vector<fs::path> files_;
  std::vector<FrameCalibration> calib_;  // one for all frames, or one per frame
  std::vector<double> stamps_, pose_stamps_;
  std::vector<Eigen::Isometry3d> poses_;
  double depth_scale_m_ = 0.001;
  std::size_t index_ = 0;
};

}  // namespace

std::unique_ptr<Recording> open_png_folder(const std::string& path, const RecordingOptions& options) {
  return std::make_unique<PngFolderRecording>(path, options);
}

}  // namespace stvl::recording::detail
