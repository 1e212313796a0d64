#include "recording/type_hash.hpp"

#include <openssl/evp.h>

#include <cstdint>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>
#include <vector>

namespace stvl::recording::detail {
namespace {

// type_description_interfaces/msg/FieldType.msg.
constexpr int kFieldTypeNested = 1;
constexpr int kFieldTypeBoundedString = 21;
constexpr int kFieldTypeBoundedWString = 22;
constexpr int kFixedArrayOffset = 48;
constexpr int kBoundedSequenceOffset = 96;
constexpr int kUnboundedSequenceOffset = 144;

// .msg primitives by their FieldType id, through rosidl_adapter's .msg -> IDL mapping (char is uint8, byte octet).
int primitive_type_id(const std::string& type) {
  static const std::map<std::string, int> kIds = {{"int8", 2},   {"uint8", 3},    {"char", 3},     {"int16", 4},
                                                  {"uint16", 5}, {"int32", 6},    {"uint32", 7},   {"int64", 8},
                                                  {"uint64", 9}, {"float32", 10}, {"float64", 11}, {"bool", 15},
                                                  {"byte", 16},  {"string", 17},  {"wstring", 18}};
  const auto it = kIds.find(type);
  if (it == kIds.end()) throw std::invalid_argument("no ROS 2 field type for the primitive '" + type + "'");
  return it->second;
}

struct FieldType {
  int type_id = 0;
  std::uint32_t capacity = 0, string_capacity = 0;
  std::string nested_type_name;
};

FieldType field_type(const MsgField& f) {
  FieldType t;
  if (f.primitive) {
    t.type_id = primitive_type_id(f.type);
    if (f.string_bound > 0 && (f.type == "string" || f.type == "wstring")) {
      t.type_id = f.type == "string" ? kFieldTypeBoundedString : kFieldTypeBoundedWString;
      t.string_capacity = f.string_bound;
    }
  } else {
    t.type_id = kFieldTypeNested;
    t.nested_type_name = full_msg_type(f.type);
  }
  switch (f.array) {
    case MsgField::Array::kNone: break;
    case MsgField::Array::kFixed: t.type_id += kFixedArrayOffset, t.capacity = f.array_size; break;
    // rosbag2's own recording (tests/recording/test_type_hash.cpp) carries the bound of [<=N] as the capacity.
    case MsgField::Array::kBounded: t.type_id += kBoundedSequenceOffset, t.capacity = f.array_size; break;
    case MsgField::Array::kUnbounded: t.type_id += kUnboundedSequenceOffset; break;
  }
  return t;
}

// Type names and field names are ROS identifiers: nothing in them needs escaping.
std::string quoted(const std::string& s) { return "\"" + s + "\""; }

std::string individual_json(const std::string& name, const MsgType& type) {
  std::vector<MsgField> fields = type.fields;
  if (fields.empty()) {  // rosidl_parser gives an empty structure this one member
    MsgField f;
    f.name = "structure_needs_at_least_one_member";
    f.type = "uint8";
    fields.push_back(f);
  }
  std::string json = "{\"type_name\": " + quoted(name) + ", \"fields\": [";
  for (std::size_t i = 0; i < fields.size(); ++i) {
    const FieldType t = field_type(fields[i]);
    json += (i ? ", " : "") + std::string("{\"name\": ") + quoted(fields[i].name) +
            ", \"type\": {\"type_id\": " + std::to_string(t.type_id) + ", \"capacity\": " + std::to_string(t.capacity) +
            ", \"string_capacity\": " + std::to_string(t.string_capacity) +
            ", \"nested_type_name\": " + quoted(t.nested_type_name) + "}}";
  }
  return json + "]}";
}

// The types of a schema by their full names, the main one as `type`.
std::map<std::string, const MsgType*> types_by_name(const std::string& type, const MsgSchema& schema) {
  std::map<std::string, const MsgType*> by_name;
  for (std::size_t i = 0; i < schema.types.size(); ++i)
    by_name.emplace(i == 0 ? full_msg_type(type) : full_msg_type(schema.types[i].name), &schema.types[i]);
  return by_name;
}

// service_msgs/msg/ServiceEventInfo and builtin_interfaces/msg/Time, as a service event uses them (fields only:
// the constants REQUEST_SENT.. are not hashed).
MsgField field(const std::string& name, const std::string& type, MsgField::Array array = MsgField::Array::kNone,
               std::uint32_t size = 0) {
  MsgField f;
  f.name = name, f.type = type, f.array = array, f.array_size = size;
  f.primitive = type.find('/') == std::string::npos;
  return f;
}
MsgType service_event_info() {
  MsgType t;
  t.name = "service_msgs/msg/ServiceEventInfo";
  t.fields = {field("event_type", "uint8"), field("stamp", "builtin_interfaces/msg/Time"),
              field("client_gid", "char", MsgField::Array::kFixed, 16), field("sequence_number", "int64")};
  return t;
}
MsgType builtin_time() {
  MsgType t;
  t.name = "builtin_interfaces/msg/Time";
  t.fields = {field("sec", "int32"), field("nanosec", "uint32")};
  return t;
}

// "pkg/srv/X_Event" from a .srv text (request, "---", response, then the sections of the types they use), which
// the parser gives as the types pkg/srv/X_Request and X_Response; the event is rosidl_parser's Service's.
TypeHash service_event_hash(const std::string& type, const std::string& text) {
  const std::string service = type.substr(0, type.size() - std::string("_Event").size());
  MsgSchema event;
  try {
    event = parse_ros2msg(type, text);
  } catch (const std::invalid_argument& e) {
    return {"", type + ": " + e.what()};
  }
  const auto parts = types_by_name(type, event);
  if (!parts.count(service + "_Response")) return {"", type + ": the service text has no '---' line"};
  event.types[0].fields = {field("info", "service_msgs/msg/ServiceEventInfo"),
                           field("request", service + "_Request", MsgField::Array::kBounded, 1),
                           field("response", service + "_Response", MsgField::Array::kBounded, 1)};
  if (!parts.count("service_msgs/msg/ServiceEventInfo")) event.types.push_back(service_event_info());
  if (!parts.count("builtin_interfaces/msg/Time")) event.types.push_back(builtin_time());
  return ros2_type_hash(type, event);
}

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

}  // namespace

std::string ros2_type_description_json(const std::string& type, const MsgSchema& schema) {
  if (schema.types.empty()) throw std::invalid_argument(type + ": an empty schema");
  const auto by_name = types_by_name(type, schema);
  // Every type the main one uses, transitively.
  std::set<std::string> referenced;
  std::vector<const MsgType*> pending = {&schema.types[0]};
  std::vector<std::string> users = {full_msg_type(type)};
  while (!pending.empty()) {
    const MsgType* t = pending.back();
    const std::string user = users.back();
    pending.pop_back(), users.pop_back();
    for (const auto& f : t->fields) {
      if (f.primitive) continue;
      const std::string name = full_msg_type(f.type);
      if (!referenced.insert(name).second) continue;
      const auto it = by_name.find(name);
      if (it == by_name.end())
        throw std::invalid_argument("no definition of " + name + " (the type of " + user + "." + f.name + ")");
      pending.push_back(it->second), users.push_back(name);
    }
  }
  std::string json = "{\"type_description\": " + individual_json(full_msg_type(type), schema.types[0]) +
                     ", \"referenced_type_descriptions\": [";
  bool first = true;
  for (const auto& name : referenced) {  // std::set: sorted by name, as Python's sorted()
    json += (first ? "" : ", ") + individual_json(name, *by_name.at(name));
    first = false;
  }
  return json + "]}";
}

TypeHash ros2_type_hash(const std::string& type, const MsgSchema& schema) {
  try {
    return {"RIHS01_" + sha256_hex(ros2_type_description_json(type, schema)), ""};
  } catch (const std::invalid_argument& e) {
    return {"", type + ": " + e.what()};
  }
}

TypeHash ros2_type_hash_of_schema(const std::string& type, const std::string& encoding, const std::string& text) {
  if (encoding != "ros2msg") return {"", type + ": a schema in " + encoding + ", not ros2msg"};
  if (text.rfind("IDL: ", 0) == 0 || text.find("\nIDL: ") != std::string::npos)
    return {"", type + ": the schema has IDL sections"};
  const std::string name = full_msg_type(type);
  if (name.find("/action/") != std::string::npos) return {"", type + ": action types are not supported"};
  if (name.find("/srv/") != std::string::npos) {
    if (!ends_with(name, "_Event")) return {"", type + ": of a service's types only events are supported"};
    return service_event_hash(name, text);
  }
  try {
    return ros2_type_hash(name, parse_ros2msg(name, text));
  } catch (const std::invalid_argument& e) {
    return {"", type + ": " + e.what()};
  }
}

std::string sha256_hex(const std::string& bytes) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int size = 0;
  if (EVP_Digest(bytes.data(), bytes.size(), digest, &size, EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("sha256_hex: OpenSSL's EVP_Digest failed");
  static const char kHex[] = "0123456789abcdef";
  std::string hex;
  for (unsigned int i = 0; i < size; ++i) hex += kHex[digest[i] >> 4], hex += kHex[digest[i] & 15];
  return hex;
}

}  // namespace stvl::recording::detail
