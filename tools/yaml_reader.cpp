#include "tools/yaml_reader.hpp"

#include <cstdint>
#include <filesystem>
#include <sstream>

namespace stvl::tools {

template <> const char* YamlMap::type_name<bool>() { return "a boolean"; }
template <> const char* YamlMap::type_name<int>() { return "an integer"; }
template <> const char* YamlMap::type_name<std::uint64_t>() { return "a non-negative integer"; }
template <> const char* YamlMap::type_name<double>() { return "a number"; }
template <> const char* YamlMap::type_name<float>() { return "a number"; }
template <> const char* YamlMap::type_name<std::string>() { return "a string"; }
template <> const char* YamlMap::type_name<std::vector<double>>() { return "a list of numbers"; }
template <> const char* YamlMap::type_name<std::vector<std::vector<double>>>() { return "a list of number lists"; }
template <> const char* YamlMap::type_name<std::vector<std::string>>() { return "a list of strings"; }

YamlMap::YamlMap(YAML::Node node, std::string file, std::string path)
    : node_(std::move(node)), file_(std::move(file)), path_(std::move(path)) {
  if (!node_.IsMap()) {
    std::ostringstream message;
    message << file_ << ":" << node_.Mark().line + 1 << ": " << (path_.empty() ? "document" : path_)
            << ": expected a mapping of keys to values";
    throw std::invalid_argument(message.str());
  }
}

bool YamlMap::has(const std::string& key) const { return static_cast<bool>(node_[key]); }

std::optional<YAML::Node> YamlMap::lookup(const std::string& key) {
  used_.insert(key);
  YAML::Node child = node_[key];
  if (!child || child.IsNull()) return std::nullopt;
  return child;
}

YamlMap YamlMap::map(const std::string& key) {
  const auto node = lookup(key);
  if (!node) fail(node_, key, "required mapping is missing");
  if (!node->IsMap()) fail(*node, key, "expected a mapping, got '" + describe(*node) + "'");
  return YamlMap(*node, file_, location(key));
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
    const auto key = entry.first.as<std::string>();
    if (used_.count(key)) continue;
    std::string known;
    for (const auto& k : used_) known += (known.empty() ? "" : ", ") + k;
    fail(entry.first, key, "unknown key (known: " + known + ")");
  }
}

void YamlMap::fail(const YAML::Node& at, const std::string& key, const std::string& message) const {
  std::ostringstream text;
  const int line = at.Mark().is_null() ? node_.Mark().line : at.Mark().line;
  text << file_ << ":" << line + 1 << ": " << location(key) << ": " << message;
  throw std::invalid_argument(text.str());
}

std::string YamlMap::describe(const YAML::Node& node) {
  if (node.IsScalar()) return node.Scalar();
  if (node.IsSequence()) return "a list";
  if (node.IsMap()) return "a mapping";
  return "null";
}

YAML::Node load_yaml_file(const std::string& file) {
  if (!std::filesystem::is_regular_file(file)) throw std::invalid_argument(file + ": no such file");
  try {
    return YAML::LoadFile(file);
  } catch (const YAML::ParserException& e) {
    throw std::invalid_argument(file + ":" + std::to_string(e.mark.line + 1) + ": YAML syntax error: " + e.msg);
  }
}

}  // namespace stvl::tools
