#include "recording/ros2msg.hpp"

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <sstream>

namespace stvl::recording::detail {
namespace {

const std::set<std::string>& primitives() {
  // rosidl_adapter's PRIMITIVE_TYPES ("time" and "duration" for ROS 1 compatibility).
  static const std::set<std::string> kPrimitives = {"bool",   "byte",   "char",    "float32", "float64", "int8",
                                                    "uint8",  "int16",  "uint16",  "int32",   "uint32",  "int64",
                                                    "uint64", "string", "wstring", "time",    "duration"};
  return kPrimitives;
}

bool is_string_type(const std::string& t) { return t == "string" || t == "wstring"; }

// Names as rosidl_adapter's ROS 1 compatible patterns: a letter, then letters, digits and '_'.
bool is_identifier(const std::string& s) {
  static const std::regex kName(R"(^[A-Za-z][A-Za-z0-9_]*$)");
  return std::regex_match(s, kName);
}

// "pkg/Type", "pkg/msg/Type" (or srv, action) -> "pkg/msg/Type"; "" for anything else.
std::string parse_type_name(const std::string& s) {
  static const std::regex kType(R"(^([a-z][a-z0-9_]*)/(?:(msg|srv|action)/)?([A-Za-z][A-Za-z0-9_]*)$)");
  std::smatch m;
  if (!std::regex_match(s, m, kType)) return "";
  return m[1].str() + "/" + (m[2].matched ? m[2].str() : std::string("msg")) + "/" + m[3].str();
}

std::string package_of(const std::string& full_type) { return full_type.substr(0, full_type.find('/')); }

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(' ');
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(' ') - b + 1);
}

// The line without its comment: from the first '#' outside a quoted value ('...' or "...", '\' escapes).
std::string strip_comment(const std::string& line) {
  char quote = 0;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (quote) {
      if (c == '\\') ++i;
      else if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '#') {
      return line.substr(0, i);
    }
  }
  return line;
}

// A positive integer (array sizes, string bounds); 0 for anything else.
std::uint32_t parse_bound(const std::string& s) {
  if (s.empty() || s.size() > 9 || s.find_first_not_of("0123456789") != std::string::npos) return 0;
  return static_cast<std::uint32_t>(std::stoul(s));
}

// A field's type string into `f`; "" or what was expected.
std::string parse_field_type(std::string t, const std::string& package, MsgField& f) {
  if (!t.empty() && t.back() == ']') {
    const auto open = t.rfind('[');
    if (open == std::string::npos) return "an array type TYPE[N], TYPE[<=N] or TYPE[]";
    std::string size = t.substr(open + 1, t.size() - open - 2);
    t.erase(open);
    if (size.empty()) {
      f.array = MsgField::Array::kUnbounded;
    } else {
      f.array = size.rfind("<=", 0) == 0 ? MsgField::Array::kBounded : MsgField::Array::kFixed;
      if (f.array == MsgField::Array::kBounded) size.erase(0, 2);
      f.array_size = parse_bound(size);
      if (f.array_size == 0) return "an array size that is an integer > 0";
    }
  }
  const auto bound = t.find("<=");
  if (bound != std::string::npos) {
    const std::string base = t.substr(0, bound);
    if (!is_string_type(base)) return "a bound (<=N) on string or wstring only";
    f.string_bound = parse_bound(t.substr(bound + 2));
    if (f.string_bound == 0) return "a string bound that is an integer > 0";
    t = base;
  }
  if (primitives().count(t)) {
    f.type = t;
    return "";
  }
  f.primitive = false;
  f.type = t.find('/') == std::string::npos && is_identifier(t) ? package + "/msg/" + t : parse_type_name(t);
  if (f.type.empty()) return "a primitive type or a message type pkg/Type, pkg/msg/Type or Type";
  return "";
}

// The value of a quoted or bare string; false when its inner quotes are not escaped.
bool unquote(std::string& s) {
  for (const char q : {'"', '\''}) {
    if (s.size() >= 2 && s.front() == q && s.back() == q) {
      std::string out;
      for (std::size_t i = 1; i + 1 < s.size(); ++i) {
        if (s[i] == '\\' && i + 2 < s.size() && s[i + 1] == q) {
          out += q, ++i;
        } else if (s[i] == q) {
          return false;
        } else {
          out += s[i];
        }
      }
      s = out;
      return true;
    }
  }
  return true;
}

bool parse_integer(const std::string& s, long double& v) {
  if (s.empty()) return false;
  errno = 0;
  char* end = nullptr;
  const bool negative = s[0] == '-';
  if (negative) {
    const long long x = std::strtoll(s.c_str(), &end, 0);
    v = static_cast<long double>(x);
  } else {
    const unsigned long long x = std::strtoull(s.c_str() + (s[0] == '+'), &end, 0);
    v = static_cast<long double>(x);
  }
  return errno == 0 && end && *end == '\0';
}

// "" when `value` fits the primitive `type` (a non-array), else what was expected.
std::string check_primitive_value(const std::string& type, std::uint32_t string_bound, std::string value) {
  if (type == "bool") {
    for (auto& c : value) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return value == "true" || value == "false" || value == "1" || value == "0" ? "" : "true, false, 1 or 0";
  }
  if (type == "float32" || type == "float64") {
    char* end = nullptr;
    std::strtod(value.c_str(), &end);
    return !value.empty() && end && *end == '\0' ? "" : "a floating point number";
  }
  if (is_string_type(type)) {
    if (!unquote(value)) return "a string whose inner quotes are escaped";
    if (string_bound && value.size() > string_bound)
      return "a string of at most " + std::to_string(string_bound) + " characters";
    return "";
  }
  if (type == "time" || type == "duration") return "no value (time and duration take none)";
  static const std::map<std::string, std::pair<long double, long double>> kRanges = {
      {"byte", {0, 255}},
      {"char", {0, 255}},
      {"int8", {-128, 127}},
      {"uint8", {0, 255}},
      {"int16", {-32768, 32767}},
      {"uint16", {0, 65535}},
      {"int32", {-2147483648.0L, 2147483647}},
      {"uint32", {0, 4294967295.0L}},
      {"int64", {-9223372036854775808.0L, 9223372036854775807.0L}},
      {"uint64", {0, 18446744073709551615.0L}}};
  const auto range = kRanges.at(type);
  long double v = 0;
  if (!parse_integer(value, v) || v < range.first || v > range.second) {
    std::ostringstream out;
    out << "an integer from " << static_cast<long long>(range.first) << " to "
        << static_cast<unsigned long long>(range.second);
    return out.str();
  }
  return "";
}

// The elements of an array value "[a, b, ...]" (strings may be quoted and hold commas).
bool split_array(const std::string& value, std::vector<std::string>& items) {
  if (value.size() < 2 || value.front() != '[' || value.back() != ']') return false;
  const std::string inner = value.substr(1, value.size() - 2);
  if (trim(inner).empty()) return true;
  std::string item;
  char quote = 0;
  for (std::size_t i = 0; i < inner.size(); ++i) {
    const char c = inner[i];
    if (quote) {
      item += c;
      if (c == '\\' && i + 1 < inner.size()) item += inner[++i];
      else if (c == quote) quote = 0;
    } else if (c == ',') {
      items.push_back(trim(item)), item.clear();
    } else {
      if (c == '"' || c == '\'') quote = c;
      item += c;
    }
  }
  items.push_back(trim(item));
  return quote == 0;
}

// "" when a field's default fits its type, else what was expected.
std::string check_default(const MsgField& f) {
  if (!f.primitive) return "no default value (a message type takes none)";
  if (f.array == MsgField::Array::kNone) return check_primitive_value(f.type, f.string_bound, f.value);
  std::vector<std::string> items;
  if (!split_array(f.value, items)) return "an array value [a, b, ...]";
  if (f.array == MsgField::Array::kFixed && items.size() != f.array_size)
    return "exactly " + std::to_string(f.array_size) + " elements";
  if (f.array == MsgField::Array::kBounded && items.size() > f.array_size)
    return "at most " + std::to_string(f.array_size) + " elements";
  for (const auto& item : items) {
    const std::string e = check_primitive_value(f.type, f.string_bound, item);
    if (!e.empty()) return "elements that are " + e;
  }
  return "";
}

// One line of a section (comment removed, trimmed, not empty) into `type`.
void parse_definition(const std::string& body, int line_no, const std::string& line, MsgType& type) {
  std::string text = body;
  if (text.rfind("@optional", 0) == 0) text = trim(text.substr(9));
  const auto space = text.find(' ');
  if (space == std::string::npos) throw MsgParseError(line_no, line, "TYPE NAME, TYPE NAME DEFAULT or TYPE NAME=VALUE");
  MsgField f;
  f.line = line_no;
  const std::string expected = parse_field_type(text.substr(0, space), package_of(type.name), f);
  if (!expected.empty()) throw MsgParseError(line_no, line, expected);
  const std::string rest = trim(text.substr(space + 1));
  std::size_t name_end = 0;
  while (name_end < rest.size() && (std::isalnum(static_cast<unsigned char>(rest[name_end])) || rest[name_end] == '_'))
    ++name_end;
  f.name = rest.substr(0, name_end);
  if (!is_identifier(f.name)) throw MsgParseError(line_no, line, "a name (a letter, then letters, digits, '_')");
  const std::string after = trim(rest.substr(name_end));
  const bool constant = !after.empty() && after[0] == '=';
  if (constant) {
    f.value = trim(after.substr(1));
    if (!f.primitive || f.array != MsgField::Array::kNone)
      throw MsgParseError(line_no, line, "a constant of a primitive, non-array type");
    if (f.value.empty()) throw MsgParseError(line_no, line, "a constant's value after '='");
  } else if (!after.empty()) {
    if (name_end < rest.size() && rest[name_end] != ' ')
      throw MsgParseError(line_no, line, "a name (a letter, then letters, digits, '_')");
    f.value = after;
  }
  if (!f.value.empty()) {
    const std::string bad = constant ? check_primitive_value(f.type, f.string_bound, f.value) : check_default(f);
    if (!bad.empty()) throw MsgParseError(line_no, line, bad);
  }
  auto& list = constant ? type.constants : type.fields;
  for (const auto& other : list)
    if (other.name == f.name) throw MsgParseError(line_no, line, "a name not used before in " + type.name);
  list.push_back(f);
}

// A service's or action's parts ("---" separated) as types: pkg/srv/Base_Request, _Response; pkg/action/Base_Goal,
// _Result, _Feedback.
std::string part_name(const std::string& main, std::size_t part) {
  std::string base = main;
  for (const char* suffix : {"_Event", "_Request", "_Response", "_FeedbackMessage", "_Goal", "_Result", "_Feedback"}) {
    const std::string s = suffix;
    if (base.size() > s.size() && base.compare(base.size() - s.size(), s.size(), s) == 0) {
      base.erase(base.size() - s.size());
      break;
    }
  }
  static const char* kSrv[] = {"_Request", "_Response"};
  static const char* kAction[] = {"_Goal", "_Result", "_Feedback"};
  const bool srv = main.find("/srv/") != std::string::npos;
  if ((srv && part >= 2) || (!srv && part >= 3)) return "";
  return base + (srv ? kSrv[part] : kAction[part]);
}

}  // namespace

MsgParseError::MsgParseError(int line_no, std::string line_text, const std::string& expected)
    : std::invalid_argument("line " + std::to_string(line_no) + ": '" + line_text.substr(0, 100) + "': expected " +
                            expected),
      line(line_no),
      text(std::move(line_text)) {}

const MsgType* MsgSchema::find(const std::string& name) const {
  const std::string full = full_msg_type(name);
  for (const auto& t : types)
    if (t.name == full) return &t;
  return nullptr;
}

std::string full_msg_type(const std::string& type) {
  const std::string full = parse_type_name(type);
  return full.empty() ? type : full;
}

MsgSchema parse_ros2msg(const std::string& type, const std::string& text) {
  MsgSchema schema;
  schema.types.push_back(MsgType{full_msg_type(type), {}, {}});
  const bool has_parts = schema.types[0].name.find("/srv/") != std::string::npos ||
                         schema.types[0].name.find("/action/") != std::string::npos;
  std::size_t part = 0;
  if (has_parts) schema.types.push_back(MsgType{part_name(schema.types[0].name, 0), {}, {}});
  bool expect_msg_line = false, in_main = true;
  std::istringstream in(text);
  int line_no = 0;
  for (std::string raw; std::getline(in, raw);) {
    ++line_no;
    if (!raw.empty() && raw.back() == '\r') raw.pop_back();
    std::string line = raw;
    for (auto& c : line)
      if (c == '\t') c = ' ';
    const std::string body = trim(strip_comment(line));
    if (body.empty()) continue;
    if (body.size() >= 3 && body.find_first_not_of('=') == std::string::npos) {
      expect_msg_line = true, in_main = false;
      continue;
    }
    if (expect_msg_line) {
      if (body.rfind("IDL:", 0) == 0)
        throw MsgParseError(line_no, raw, "MSG: pkg/Type (an IDL: section, ros2idl text, is not read)");
      if (body.rfind("MSG:", 0) != 0) throw MsgParseError(line_no, raw, "MSG: pkg/Type after a line of '='");
      const std::string name = parse_type_name(trim(body.substr(4)));
      if (name.empty()) throw MsgParseError(line_no, raw, "MSG: pkg/Type or MSG: pkg/msg/Type");
      // A type defined twice (older rosbag2 repeats shared dependencies): the first definition is the one found.
      schema.types.push_back(MsgType{name, {}, {}});
      expect_msg_line = false;
      continue;
    }
    if (body == "---") {
      const std::string next = in_main && has_parts ? part_name(schema.types[0].name, ++part) : "";
      if (next.empty())
        throw MsgParseError(line_no, raw, "a field or constant ('---' separates a service's or action's parts only)");
      schema.types.push_back(MsgType{next, {}, {}});
      continue;
    }
    parse_definition(body, line_no, raw, schema.types.back());
  }
  if (expect_msg_line) throw MsgParseError(line_no, "", "MSG: pkg/Type after the last line of '='");
  return schema;
}

}  // namespace stvl::recording::detail
