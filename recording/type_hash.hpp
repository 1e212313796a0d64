#pragma once
// ROS 2's type description hash (REP-2011, "RIHS01_" + SHA-256 hex), as rosidl_generator_type_description computes
// it and rosbag2 writes it into metadata.yaml (type_description_hash). Not part of the interface.
//
// The hashed text is the JSON of the type's description: {"type_description": {"type_name": "pkg/msg/T", "fields":
// [{"name": ..., "type": {"type_id", "capacity", "string_capacity", "nested_type_name"}}, ...]},
// "referenced_type_descriptions": [every type used transitively, sorted by name]} with Python's separators
// (", ", ": "). Constants and default values are not hashed. Field type ids are type_description_interfaces'
// FieldType (char is uint8, byte is octet, as rosidl_adapter maps .msg to IDL; +48 for [N], +96 for [<=N], +144
// for []); capacity is N of [N] and [<=N]; string_capacity is N of string<=N. A message without fields has one,
// uint8 structure_needs_at_least_one_member.
#include <string>

#include "recording/ros2msg.hpp"

namespace stvl::recording::detail {

// A type's hash, or why there is none (rosbag2 writes "" then too).
struct TypeHash {
  std::string rihs01;  // "RIHS01_<64 hex digits>", or empty
  std::string reason;  // empty when rihs01 is set
};

// The RIHS01 hash of `type` ("pkg/msg/T" or "pkg/T") whose fields are schema.types[0]'s and whose referenced
// types are found in `schema` (by "pkg/msg/U" or "pkg/U"); empty with a reason when one is missing.
TypeHash ros2_type_hash(const std::string& type, const MsgSchema& schema);

// The hash of a type from the schema a bag carries for it (MCAP schema encoding "ros2msg"): a message's ros2msg
// text, or for a service event "pkg/srv/X_Event" the service's text (request, "---", response, then the sections
// of the types they use). Empty with a reason for another encoding (ros2idl), an action type, a text that does
// not parse, or a referenced type it lacks.
TypeHash ros2_type_hash_of_schema(const std::string& type, const std::string& encoding, const std::string& text);

// The JSON text ros2_type_hash() hashes (for tests and diagnostics); throws std::invalid_argument naming a
// referenced type whose definition is missing.
std::string ros2_type_description_json(const std::string& type, const MsgSchema& schema);

// SHA-256 of `bytes` as 64 lowercase hex digits (OpenSSL's libcrypto).
std::string sha256_hex(const std::string& bytes);

}  // namespace stvl::recording::detail
