#include "config/yaml_reader.hpp"

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "common/enum_names.hpp"

namespace stvl::config {

template <>
const char* YamlMap::type_name<bool>() {
  return "a boolean";
}
template <>
const char* YamlMap::type_name<int>() {
  return "an integer";
}
template <>
const char* YamlMap::type_name<std::uint64_t>() {
  return "a non-negative integer";
}
template <>
const char* YamlMap::type_name<double>() {
  return "a number";
}
template <>
const char* YamlMap::type_name<float>() {
  return "a number";
}
template <>
const char* YamlMap::type_name<std::string>() {
  return "a string";
}
template <>
const char* YamlMap::type_name<std::vector<double>>() {
  return "a list of numbers";
}
template <>
const char* YamlMap::type_name<std::vector<std::vector<double>>>() {
  return "a list of number lists";
}
template <>
const char* YamlMap::type_name<std::vector<std::string>>() {
  return "a list of strings";
}

namespace {
int line_of(const YAML::Mark& mark) { return mark.is_null() || mark.line < 0 ? 1 : mark.line + 1; }
std::string describe_scalar(const YAML::Node& node) { return node.IsScalar() ? node.Scalar() : "a list"; }
}  // namespace

YamlMap::YamlMap(YAML::Node node, std::string file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)), line_(line_of(node_.Mark())) {
  const std::string where = path_.empty() ? "document" : path_;
  if (!node_.IsMap()) {
    std::ostringstream message;
    message << file_ << ":" << line_of(node_.Mark()) << ": " << where << ": expected a mapping of keys to values";
    throw std::invalid_argument(message.str());
  }
  // yaml-cpp keeps duplicate keys and lookups see only the first, so a repeated key would be ignored silently.
  std::set<std::string> seen;
  for (const auto& entry : node_) {
    if (!entry.first.IsScalar()) {
      std::ostringstream message;
      message << file_ << ":" << line_of(entry.first.Mark()) << ": " << where << ": keys must be plain names, got "
              << describe(entry.first);
      throw std::invalid_argument(message.str());
    }
    const std::string key = entry.first.Scalar();
    if (!seen.insert(key).second) fail(entry.first, key, "duplicate key");
  }
}

bool YamlMap::has(const std::string& key) const { return static_cast<bool>(node_[key]); }

std::optional<YAML::Node> YamlMap::lookup(const std::string& key) {
  used_.insert(key);
  YAML::Node child = node_[key];
  if (!child) return std::nullopt;
  return child;
}

YAML::Node YamlMap::key_node(const std::string& key) const {
  for (const auto& entry : node_)
    if (entry.first.Scalar() == key) return entry.first;
  return YAML::Node();
}

YamlMap YamlMap::map(const std::string& key) {
  const auto node = lookup(key);
  if (!node) fail(YAML::Node(), key, "required mapping is missing");
  if (!node->IsMap()) fail(*node, key, "expected a mapping, got '" + describe(*node) + "'");
  YamlMap child(*node, file_, location(key));
  child.line_ = line_of(key_node(key).Mark());
  return child;
}

std::vector<YamlMap> YamlMap::list_of_maps(const std::string& key) {
  std::vector<YamlMap> maps;
  const auto node = lookup(key);
  if (!node) return maps;
  if (!node->IsSequence()) fail(*node, key, "expected a list");
  for (std::size_t i = 0; i < node->size(); ++i) {
    const YAML::Node item = (*node)[i];
    const std::string item_key = key + "[" + std::to_string(i) + "]";
    if (!item.IsMap()) fail(item, item_key, "expected a mapping");
    maps.emplace_back(item, file_, location(item_key));
  }
  return maps;
}

YAML::Node YamlMap::raw(const std::string& key) {
  const auto node = lookup(key);
  return node ? *node : YAML::Node();
}

void YamlMap::finish() const {
  for (const auto& entry : node_) {
    const std::string key = entry.first.Scalar();
    if (used_.count(key)) continue;
    std::string known;
    for (const auto& k : used_) known += (known.empty() ? "" : ", ") + k;
    const std::string nearest = nearest_name(key, {used_.begin(), used_.end()});
    fail(entry.first, key,
         "unknown key" + (nearest.empty() ? std::string() : "; did you mean '" + nearest + "'?") + " (known: " + known +
             ")");
  }
}

std::string YamlMap::where(const std::string& key) const {
  int line = line_;
  if (const YAML::Node k = key_node(key); !k.IsNull()) line = line_of(k.Mark());
  return file_ + ":" + std::to_string(line) + ": " + location(key);
}

void YamlMap::fail(const YAML::Node& at, const std::string& key, const std::string& message) const {
  std::ostringstream text;
  int line = line_;
  if (!at.IsNull() && !at.Mark().is_null()) {
    line = line_of(at.Mark());
  } else if (const YAML::Node k = key_node(key); !k.IsNull()) {
    line = line_of(k.Mark());
  }
  text << file_ << ":" << line << ": " << location(key) << ": " << message;
  throw std::invalid_argument(text.str());
}

std::string YamlMap::describe(const YAML::Node& node) {
  if (node.IsScalar()) return node.Scalar();
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a mapping";
  return "nothing";
}

void set_yaml_path(YAML::Node& root, const std::string& assignment) {
  const auto fail = [&](const std::string& message) {
    throw std::invalid_argument("--set " + assignment + ": " + message);
  };
  const std::size_t equals = assignment.find('=');
  if (equals == std::string::npos || equals == 0) fail("expected KEY=VALUE");
  const std::string path = assignment.substr(0, equals);
  YAML::Node value;
  try {
    value = YAML::Load(assignment.substr(equals + 1));
  } catch (const YAML::Exception& e) {
    fail("the value is not YAML: " + e.msg);
  }
  if (!root.IsMap()) fail("the document is not a mapping");
  // Steps: a key, then any number of [index]; separated by dots.
  YAML::Node node = root;
  std::size_t at = 0;
  std::string walked;
  while (at < path.size()) {
    const std::size_t end = path.find_first_of(".[", at);
    const std::string key = path.substr(at, end == std::string::npos ? std::string::npos : end - at);
    if (key.empty() || key.find_first_of("] ") != std::string::npos) fail("malformed key '" + path + "'");
    walked += (walked.empty() ? "" : ".") + key;
    if (!node.IsMap()) fail(walked + ": its parent holds '" + describe_scalar(node) + "', not a mapping");
    at = end == std::string::npos ? path.size() : end;
    const bool last_key = at == path.size();
    if (last_key) {
      node[key] = value;
      return;
    }
    YAML::Node child = node[key];
    if (!child || child.IsNull()) {
      if (path[at] == '[') fail(walked + ": no such list");
      node[key] = YAML::Node(YAML::NodeType::Map);
      child.reset(node[key]);
    }
    while (at < path.size() && path[at] == '[') {
      const std::size_t close = path.find(']', at);
      const std::string digits = close == std::string::npos ? "" : path.substr(at + 1, close - at - 1);
      if (digits.empty() || digits.find_first_not_of("0123456789") != std::string::npos || digits.size() > 6)
        fail("malformed index in '" + path + "'");
      const std::size_t index = std::stoul(digits);
      if (!child.IsSequence()) fail(walked + ": not a list");
      if (index >= child.size())
        fail(walked + "[" + digits + "]: the list has " + std::to_string(child.size()) + " items");
      walked += "[" + digits + "]";
      at = close + 1;
      if (at == path.size()) {
        child[index] = value;
        return;
      }
      YAML::Node item = child[index];
      child.reset(item);
    }
    if (path[at] != '.') fail("malformed key '" + path + "'");
    ++at;
    node.reset(child);  // operator= would overwrite the node's contents (yaml-cpp's reference semantics)
  }
  fail("malformed key '" + path + "'");
}

YAML::Node load_yaml_string(const std::string& text, const std::string& file_name) {
  try {
    return YAML::Load(text);
  } catch (const YAML::ParserException& e) {
    throw std::invalid_argument(file_name + ":" + std::to_string(line_of(e.mark)) + ": YAML syntax error: " + e.msg);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(file_name + ": cannot read: " + e.msg);
  }
}

YAML::Node load_yaml_file(const std::string& file) {
  std::error_code error;
  if (!std::filesystem::exists(file, error)) throw std::invalid_argument(file + ": no such file");
  if (!std::filesystem::is_regular_file(file, error)) throw std::invalid_argument(file + ": not a regular file");
  std::ifstream in(file, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in) throw std::invalid_argument(file + ": cannot read");
  return load_yaml_string(text.str(), file);
}

}  // namespace stvl::config
