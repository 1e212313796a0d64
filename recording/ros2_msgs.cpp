#include "recording/ros2_msgs.hpp"

#include <functional>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include "recording/cdr.hpp"
#include "recording/ros2msg.hpp"

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
      {"nav_msgs/Path", "std_msgs/Header header\ngeometry_msgs/PoseStamped[] poses\n"},
  };
  return defs;
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
    const MsgSchema schema = parse_ros2msg(t, it->second);
    for (const auto& f : schema.types.front().fields) {
      if (f.primitive) continue;
      const std::string dep = short_type(f.type);
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

namespace {

// How a field reads in an error: "uint32 height", "std_msgs/msg/Header header", "float64[9] k".
std::string describe(const MsgField& f) {
  std::string t = f.type;
  if (f.string_bound) t += "<=" + std::to_string(f.string_bound);
  if (f.array == MsgField::Array::kFixed) t += "[" + std::to_string(f.array_size) + "]";
  if (f.array == MsgField::Array::kBounded) t += "[<=" + std::to_string(f.array_size) + "]";
  if (f.array == MsgField::Array::kUnbounded) t += "[]";
  return t + " " + f.name;
}

// The first `count` fields of `ours` are `recorded`'s first fields, with the same types, and every message type
// they use that the schema defines has exactly our fields (so the bytes decoded sit where the decoder reads them).
// "" or what differs.
std::string layout_difference(const MsgSchema& ours_schema, const MsgType& ours, const MsgSchema& recorded_schema,
                              const MsgType& recorded, std::size_t count) {
  if (recorded.fields.size() < count)
    return recorded.name + " has " + std::to_string(recorded.fields.size()) + " fields, expected at least " +
           std::to_string(count);
  for (std::size_t i = 0; i < count; ++i) {
    const MsgField& o = ours.fields[i];
    const MsgField& r = recorded.fields[i];
    if (describe(o) != describe(r))
      return recorded.name + " field " + std::to_string(i + 1) + " is '" + describe(r) + "', expected '" + describe(o) +
             "'";
    if (o.primitive) continue;
    const MsgType* o_type = ours_schema.find(o.type);
    const MsgType* r_type = recorded_schema.find(r.type);
    if (!r_type) continue;  // not defined in the schema: the name, the same as ours, stands for the layout
    if (r_type->fields.size() != o_type->fields.size())
      return r.type + " has " + std::to_string(r_type->fields.size()) + " fields, expected " +
             std::to_string(o_type->fields.size());
    const std::string nested = layout_difference(ours_schema, *o_type, recorded_schema, *r_type, o_type->fields.size());
    if (!nested.empty()) return nested;
  }
  return "";
}

}  // namespace

void check_ros2_schema(const std::string& type, const std::string& definition, const std::string& what) {
  MsgSchema recorded;
  try {
    recorded = parse_ros2msg(type, definition);
  } catch (const MsgParseError& e) {
    throw std::invalid_argument(what + ": the schema of " + type + " does not parse (" + e.what() + ")");
  }
  // The fields each decoder reads, in order: a prefix of the type's fields.
  static const std::map<std::string, std::size_t> kDecoded = {
      {"sensor_msgs/Image", 7}, {"sensor_msgs/CameraInfo", 6}, {"tf2_msgs/TFMessage", 1}, {"nav_msgs/Odometry", 3}};
  const auto it = kDecoded.find(short_type(type));
  if (it == kDecoded.end()) return;
  const MsgSchema ours = parse_ros2msg(it->first, ros2_definition(it->first));
  const std::string difference =
      layout_difference(ours, ours.types.front(), recorded, recorded.types.front(), it->second);
  if (!difference.empty())
    throw std::invalid_argument(what + ": the schema of " + type + " does not have the fields of " + type + " (" +
                                difference + ")");
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
