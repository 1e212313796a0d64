#include "robot_description/package_path.hpp"

#include <filesystem>
#include <stdexcept>

#include "common/enum_names.hpp"

namespace stvl::robot_description {
namespace {

namespace fs = std::filesystem;

std::string listed(const std::vector<std::string>& items) { return "[" + joined(items) + "]"; }

bool starts_with(const std::string& text, const std::string& prefix) { return text.rfind(prefix, 0) == 0; }

std::string existing_file(const fs::path& path, const std::string& uri) {
  if (fs::is_regular_file(path)) return fs::absolute(path).lexically_normal().string();
  throw std::invalid_argument("mesh file '" + uri + "' not found: no file " + path.string());
}

}  // namespace

std::string resolve_package_uri(const std::string& uri, const std::string& urdf_dir,
                                const std::vector<std::string>& package_path) {
  if (uri.empty()) throw std::invalid_argument("empty mesh file name");
  const std::string package_scheme = "package://";
  if (!starts_with(uri, package_scheme)) {
    std::string path = uri;
    if (starts_with(uri, "file://")) path = uri.substr(7);
    if (path.find("://") != std::string::npos)
      throw std::invalid_argument("mesh file '" + uri + "': only package://, file:// and plain paths are read");
    const fs::path p(path);
    return existing_file(p.is_absolute() ? p : fs::path(urdf_dir.empty() ? "." : urdf_dir) / p, uri);
  }
  const std::string rest_of_uri = uri.substr(package_scheme.size());
  const std::size_t slash = rest_of_uri.find('/');
  const std::string name = rest_of_uri.substr(0, slash);
  const std::string rest = slash == std::string::npos ? "" : rest_of_uri.substr(slash + 1);
  if (name.empty() || rest.empty())
    throw std::invalid_argument("mesh file '" + uri + "': expected package://NAME/path/to/file");
  if (package_path.empty())
    throw std::invalid_argument("mesh file '" + uri + "' names package '" + name +
                                "' but robot.package_path is empty: add the folder that holds '" + name +
                                "' (or the package folder itself)");
  std::vector<std::string> looked_at;
  for (const auto& entry : package_path) {
    fs::path root = fs::path(entry).lexically_normal();
    if (root.filename().empty()) root = root.parent_path();  // "dir/" normalizes to "dir/" with an empty name
    std::vector<fs::path> packages{root / name};
    if (root.filename() == name) packages.push_back(root);
    for (const fs::path& package : packages) {
      if (!fs::is_directory(package)) continue;
      const fs::path file = package / rest;
      if (fs::is_regular_file(file)) return fs::absolute(file).lexically_normal().string();
      looked_at.push_back(file.string());
    }
  }
  if (looked_at.empty())
    throw std::invalid_argument("mesh file '" + uri + "': package '" + name + "' not found in robot.package_path " +
                                listed(package_path) + " (a package is a folder named '" + name +
                                "' inside an entry, or an entry named '" + name + "')");
  throw std::invalid_argument("mesh file '" + uri + "' not found: looked at " + listed(looked_at) +
                              " (robot.package_path " + listed(package_path) + ")");
}

}  // namespace stvl::robot_description
