#include "recording/ros2_msgs.hpp"

#include <functional>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>

#include "recording/cdr.hpp"

namespace stvl::recording::detail {
namespace {

// The .msg files of the types we write, comments left out (readers parse the fields, not the prose).
const std::map<std::string, std::string>& definitions() {
  static const std::map<std::string, std::string> defs = {
      {"builtin_interfaces/Time", "int32 sec\nuint32 nanosec\n"},
      {"std_msgs/Header", "builtin_interfaces/Time stamp\nstring frame_id\n"},
      {"rosgraph_msgs/Clock", "builtin_interfaces/Time clock\n"},
      {"sensor_msgs/Image",
       "std_msgs/Header header\nuint32 height\nuint32 width\nstring encoding\nuint8 is_bigendian\nuint32 step\n"
       "uint8[] data\n"},
      {"sensor_msgs/RegionOfInterest",
       "uint32 x_offset\nuint32 y_offset\nuint32 height\nuint32 width\nbool do_rectify\n"},
      {"sensor_msgs/CameraInfo",
       "std_msgs/Header header\nuint32 height\nuint32 width\nstring distortion_model\nfloat64[] d\nfloat64[9] k\n"
       "float64[9] r\nfloat64[12] p\nuint32 binning_x\nuint32 binning_y\nRegionOfInterest roi\n"},
      {"sensor_msgs/PointField",
       "uint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\nuint8 UINT32=6\nuint8 FLOAT32=7\n"
       "uint8 FLOAT64=8\nstring name\nuint32 offset\nuint8 datatype\nuint32 count\n"},
      {"sensor_msgs/PointCloud2",
       "std_msgs/Header header\nuint32 height\nuint32 width\nPointField[] fields\nbool is_bigendian\n"
       "uint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n"},
      {"geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n"},
      {"geometry_msgs/Quaternion", "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n"},
      {"geometry_msgs/Pose", "Point position\nQuaternion orientation\n"},
      {"geometry_msgs/PoseStamped", "std_msgs/Header header\nPose pose\n"},
      {"geometry_msgs/PoseWithCovariance", "Pose pose\nfloat64[36] covariance\n"},
      {"geometry_msgs/Twist", "Vector3 linear\nVector3 angular\n"},
      {"geometry_msgs/TwistWithCovariance", "Twist twist\nfloat64[36] covariance\n"},
      {"geometry_msgs/Transform", "Vector3 translation\nQuaternion rotation\n"},
      {"geometry_msgs/TransformStamped", "std_msgs/Header header\nstring child_frame_id\nTransform transform\n"},
      {"tf2_msgs/TFMessage", "geometry_msgs/TransformStamped[] transforms\n"},
      {"nav_msgs/Odometry",
       "std_msgs/Header header\nstring child_frame_id\ngeometry_msgs/PoseWithCovariance pose\n"
       "geometry_msgs/TwistWithCovariance twist\n"},
      {"nav_msgs/MapMetaData",
       "builtin_interfaces/Time map_load_time\nfloat32 resolution\nuint32 width\nuint32 height\ngeometry_msgs/Pose "
       "origin\n"},
      {"nav_msgs/OccupancyGrid", "std_msgs/Header header\nMapMetaData info\nint8[] data\n"},
  };
  return defs;
}

const std::set<std::string> kPrimitives = {"bool",   "byte",    "char",    "int8",   "uint8",
                                           "int16",  "uint16",  "int32",   "uint32", "int64",
                                           "uint64", "float32", "float64", "string", "wstring"};

struct Field {
  std::string type, name;
  bool constant = false;
};

// The base type of a field type ("PointField[]" -> "PointField", "string<=5" -> "string").
std::string base_type(const std::string& type) {
  std::string t = type.substr(0, type.find('['));
  return t.substr(0, t.find("<="));
}

// Parses one section of ros2msg text; false for a line that is not a field, a constant or a comment.
bool parse_line(std::string line, Field& field, bool& empty) {
  static const std::regex kField(
      R"(^\s*([A-Za-z][A-Za-z0-9_]*(?:/(?:msg/)?[A-Za-z][A-Za-z0-9_]*)?(?:<=\d+)?(?:\[(?:<=)?\d*\])?)\s+([A-Za-z][A-Za-z0-9_]*)\s*(=.*|\s+\S.*)?$)");
  const auto hash = line.find('#');
  if (hash != std::string::npos && line.find('=') == std::string::npos) line.erase(hash);
  empty = line.find_first_not_of(" \t\r") == std::string::npos;
  if (empty) return true;
  std::smatch m;
  if (!std::regex_match(line, m, kField)) return false;
  field.type = m[1], field.name = m[2];
  field.constant = m[3].matched && m[3].str()[0] == '=';
  return true;
}

}  // namespace

std::string short_type(const std::string& type) {
  const auto at = type.find("/msg/");
  return at == std::string::npos ? type : type.substr(0, at) + type.substr(at + 4);
}

std::string ros2_definition(const std::string& type) {
  const std::string root = short_type(type);
  std::vector<std::string> order;
  std::set<std::string> seen;
  std::function<void(const std::string&)> visit = [&](const std::string& t) {
    const auto it = definitions().find(t);
    if (it == definitions().end()) throw std::logic_error("ros2_definition: no definition of " + t);
    std::istringstream in(it->second);
    for (std::string line; std::getline(in, line);) {
      Field f;
      bool empty = false;
      if (!parse_line(line, f, empty) || empty) continue;
      std::string dep = base_type(f.type);
      if (kPrimitives.count(dep)) continue;
      if (dep.find('/') == std::string::npos) dep = t.substr(0, t.find('/')) + "/" + dep;
      if (seen.insert(dep).second) {
        order.push_back(dep);
        visit(dep);
      }
    }
  };
  seen.insert(root);
  visit(root);
  std::string text = definitions().at(root);
  for (const auto& dep : order) {
    // "MSG: pkg/Type", as the fields name it: @foxglove/rosmsg (Foxglove, Lichtblick) resolves those names only.
    text += std::string(80, '=') + "\nMSG: " + dep + "\n" + definitions().at(dep);
  }
  return text;
}

void check_ros2_schema(const std::string& type, const std::string& definition, const std::string& what) {
  std::istringstream in(definition);
  std::vector<std::string> main_fields;
  bool in_main = true;
  int line_no = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    if (line.find_first_not_of('=') == std::string::npos && line.size() >= 3) {
      in_main = false;
      continue;
    }
    if (line.rfind("MSG:", 0) == 0) {
      in_main = false;
      continue;
    }
    Field f;
    bool empty = false;
    if (!parse_line(line, f, empty)) {
      throw std::invalid_argument(what + ": the schema of " + type + " does not parse (line " +
                                  std::to_string(line_no) + ": '" + line.substr(0, 80) + "')");
    }
    if (!empty && in_main && !f.constant) main_fields.push_back(f.name);
  }
  static const std::map<std::string, std::vector<std::string>> kDecoded = {
      {"sensor_msgs/Image", {"header", "height", "width", "encoding", "is_bigendian", "step", "data"}},
      {"sensor_msgs/CameraInfo", {"header", "height", "width", "distortion_model", "d", "k"}},
      {"tf2_msgs/TFMessage", {"transforms"}},
      {"nav_msgs/Odometry", {"header", "child_frame_id", "pose"}},
  };
  const auto it = kDecoded.find(short_type(type));
  if (it == kDecoded.end()) return;
  const auto& expected = it->second;
  bool ok = main_fields.size() >= expected.size();
  for (std::size_t i = 0; ok && i < expected.size(); ++i) ok = main_fields[i] == expected[i];
  if (!ok) {
    std::string got;
    for (const auto& f : main_fields) got += (got.empty() ? "" : " ") + f;
    throw std::invalid_argument(what + ": the schema of " + type + " does not have the fields of " + type +
                                " (got: " + (got.empty() ? "none" : got) + ")");
  }
}

namespace {
Stamp get_stamp(CdrReader& r) {
  Stamp s;
  s.sec = r.get<std::int32_t>();
  s.nanosec = r.get<std::uint32_t>();
  return s;
}
}  // namespace

ImageMsg decode_image(const std::uint8_t* data, std::size_t size, const std::string& what, bool header_only) {
  CdrReader r(data, size, what);
  ImageMsg m;
  m.stamp = get_stamp(r);
  m.frame_id = r.get_string();
  m.height = r.get<std::uint32_t>();
  m.width = r.get<std::uint32_t>();
  m.encoding = r.get_string();
  if (header_only) return m;
  m.is_bigendian = r.get<std::uint8_t>() != 0;
  m.step = r.get<std::uint32_t>();
  const auto bytes = r.get_bytes();
  m.data = bytes.first, m.data_size = bytes.second;
  return m;
}

CameraInfoMsg decode_camera_info(const std::uint8_t* data, std::size_t size, const std::string& what) {
  CdrReader r(data, size, what);
  CameraInfoMsg m;
  m.stamp = get_stamp(r);
  r.get_string();
  m.height = r.get<std::uint32_t>();
  m.width = r.get<std::uint32_t>();
  r.get_string();
  const std::uint32_t nd = r.get_count(8);
  for (std::uint32_t i = 0; i < nd; ++i) r.get<double>();
  r.get_array(m.k, 9);
  return m;
}

std::vector<TransformMsg> decode_tf(const std::uint8_t* data, std::size_t size, const std::string& what) {
  CdrReader r(data, size, what);
  const std::uint32_t n = r.get_count(8 + 4 + 4 + 7 * 8);
  std::vector<TransformMsg> out(n);
  for (auto& t : out) {
    t.stamp = get_stamp(r);
    t.parent = r.get_string();
    t.child = r.get_string();
    r.get_array(t.t, 3);
    r.get_array(t.q, 4);
  }
  return out;
}

OdometryMsg decode_odometry(const std::uint8_t* data, std::size_t size, const std::string& what) {
  CdrReader r(data, size, what);
  OdometryMsg m;
  m.stamp = get_stamp(r);
  m.frame_id = r.get_string();
  m.child_frame_id = r.get_string();
  r.get_array(m.p, 3);
  r.get_array(m.q, 4);
  return m;
}

}  // namespace stvl::recording::detail
