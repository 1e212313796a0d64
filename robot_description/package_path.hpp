#pragma once
// Where a URDF's mesh file names point: `package://NAME/rest` against a package path (ROS_PACKAGE_PATH's idea,
// without a ROS installation), `file://` URIs, and plain paths relative to the URDF's folder.
#include <string>
#include <vector>

namespace stvl::robot_description {

// The absolute, existing file `uri` names.
//   package://NAME/rest  NAME is a folder NAME directly inside an entry of package_path, or the entry itself when
//                        its last component is NAME; entries are tried in order, the first holding `rest` wins.
//   file:///abs, file://rel, plain paths: a relative one is taken against urdf_dir.
// Throws std::invalid_argument naming the URI and what was searched: package:// with an empty package_path, a
// package found in no entry, a file missing (every place looked at).
std::string resolve_package_uri(const std::string& uri, const std::string& urdf_dir,
                                const std::vector<std::string>& package_path);

}  // namespace stvl::robot_description
