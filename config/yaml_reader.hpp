#pragma once
// Strict reading of YAML mappings: every key must be known, every value must have the expected type, and
// each error names the file, the line and the key (for example
// "scenarios/x.yaml:12: map.voxel_sze: unknown key (known: voxel_size, voxel_decay, ...)").
#include <yaml-cpp/yaml.h>

#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

namespace stvl::config {

class YamlMap {
 public:
  // `path` is the dotted location of this mapping in the document ("" for the root).
  YamlMap(YAML::Node node, std::string file, std::string path);

  bool has(const std::string& key) const;
  // Reads `key` into `value` when present (the default stays otherwise); type errors throw.
  template <typename T>
  void get(const std::string& key, T& value) {
    if (const auto node = lookup(key)) value = convert<T>(*node, key);
  }
  template <typename T>
  void require(const std::string& key, T& value) {
    const auto node = lookup(key);
    if (!node) fail(YAML::Node(), key, "required key is missing");
    value = convert<T>(*node, key);
  }
  YamlMap map(const std::string& key);  // a nested mapping (required)
  std::vector<YamlMap> list_of_maps(const std::string& key);
  YAML::Node raw(const std::string& key);  // marks the key used; null node when absent

  // Throws on any key that was never read.
  void finish() const;

  // Names the line of `at`; of the key itself when `at` is empty or null; of this mapping's own key when `key`
  // is absent too.
  [[noreturn]] void fail(const YAML::Node& at, const std::string& key, const std::string& message) const;
  const std::string& file() const { return file_; }
  // Dotted location of `key`; of this mapping itself for an empty key.
  std::string location(const std::string& key) const {
    return path_.empty() ? key : key.empty() ? path_ : path_ + "." + key;
  }
  // "file:line: dotted.key" of `key` (of this mapping's line when absent), as fail() would name it.
  std::string where(const std::string& key) const;

 private:
  std::optional<YAML::Node> lookup(const std::string& key);
  YAML::Node key_node(const std::string& key) const;  // null node when absent
  template <typename T>
  T convert(const YAML::Node& node, const std::string& key) const {
    if (node.IsNull()) fail(node, key, std::string("expected ") + type_name<T>() + ", got nothing");
    try {
      return node.as<T>();
    } catch (const YAML::Exception&) {
      fail(node, key, std::string("expected ") + type_name<T>() + ", got '" + describe(node) + "'");
    }
  }
  template <typename T>
  static const char* type_name();
  static std::string describe(const YAML::Node& node);

  YAML::Node node_;
  std::string file_;
  std::string path_;
  std::set<std::string> used_;
  int line_;  // 1-based line of the key that holds this mapping (of the mapping itself for the root)
};

// Applies one command-line assignment "dotted.key[index].key=VALUE" to a document: VALUE is read as YAML (so
// "0.1", "true", "[[0, 0], [8, 0]]" keep their types), missing mappings on the way are created, list indices
// must exist. Throws std::invalid_argument starting "--set ASSIGNMENT: " for a malformed assignment, a path
// through a value that is not a mapping or list, or an index out of range. Unknown keys are left to the
// strict reader, which names them as it names a file's.
void set_yaml_path(YAML::Node& root, const std::string& assignment);

// Loads a YAML file or text; parse errors name the file and line.
YAML::Node load_yaml_file(const std::string& file);
YAML::Node load_yaml_string(const std::string& text, const std::string& file_name);

}  // namespace stvl::config
