#include "robot_description/urdf_model.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

#include <tinyxml2.h>

#include "common/enum_names.hpp"
#include "robot_description/package_path.hpp"

namespace stvl::robot_description {
namespace {

namespace fs = std::filesystem;
using tinyxml2::XMLElement;

constexpr EnumName<UrdfJointType> kJointTypes[] = {
    {UrdfJointType::kFixed, "fixed"},           {UrdfJointType::kRevolute, "revolute"},
    {UrdfJointType::kContinuous, "continuous"}, {UrdfJointType::kPrismatic, "prismatic"},
    {UrdfJointType::kFloating, "floating"},     {UrdfJointType::kPlanar, "planar"}};

std::string lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

// Reads one file's elements; every error names the file and the element's line.
class Reader {
 public:
  Reader(std::string file, std::vector<std::string> package_path)
      : file_(std::move(file)), package_path_(std::move(package_path)), dir_(fs::path(file_).parent_path().string()) {}

  [[noreturn]] void fail(const XMLElement* e, const std::string& what) const {
    throw std::invalid_argument(file_ + ":" + std::to_string(e ? e->GetLineNum() : 0) + ": " + what);
  }

  std::string text(const XMLElement* e, const char* attribute) const {
    const char* value = e->Attribute(attribute);
    if (!value) fail(e, "<" + std::string(e->Name()) + "> needs the attribute " + attribute);
    return value;
  }

  const XMLElement* child(const XMLElement* e, const char* name) const {
    const XMLElement* c = e->FirstChildElement(name);
    if (!c) fail(e, "<" + std::string(e->Name()) + "> needs a <" + name + "> element");
    return c;
  }

  // `count` finite numbers separated by white space; `fallback` (when given) if the attribute is absent.
  std::vector<double> numbers(const XMLElement* e, const char* attribute, std::size_t count,
                              std::optional<std::vector<double>> fallback = std::nullopt) const {
    const char* value = e->Attribute(attribute);
    if (!value) {
      if (fallback) return *fallback;
      fail(e, "<" + std::string(e->Name()) + "> needs the attribute " + attribute);
    }
    std::vector<double> out;
    std::istringstream in(value);
    for (std::string token; in >> token;) {
      double x = 0;
      const char* begin = token.c_str() + (token[0] == '+' ? 1 : 0);
      const auto [end, error] = std::from_chars(begin, token.c_str() + token.size(), x);
      if (error != std::errc() || end != token.c_str() + token.size() || !std::isfinite(x))
        fail(e, std::string(attribute) + "=\"" + value + "\": '" + token + "' is not a finite number");
      out.push_back(x);
    }
    if (out.size() != count)
      fail(e, std::string(attribute) + "=\"" + value + "\": expected " + std::to_string(count) + " number" +
                  (count == 1 ? "" : "s"));
    return out;
  }

  double number(const XMLElement* e, const char* attribute, std::optional<double> fallback = std::nullopt) const {
    std::optional<std::vector<double>> one;
    if (fallback) one = std::vector<double>{*fallback};
    return numbers(e, attribute, 1, one)[0];
  }

  Eigen::Isometry3d origin(const XMLElement* owner) const {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    const XMLElement* o = owner->FirstChildElement("origin");
    if (!o) return T;
    const auto xyz = numbers(o, "xyz", 3, std::vector<double>{0, 0, 0});
    const auto rpy = numbers(o, "rpy", 3, std::vector<double>{0, 0, 0});
    T.translation() = Eigen::Vector3d(xyz[0], xyz[1], xyz[2]);
    T.linear() = rpy_to_matrix(Eigen::Vector3d(rpy[0], rpy[1], rpy[2]));
    return T;
  }

  UrdfGeometry collision_geometry(const XMLElement* collision, const std::string& link) const {
    const XMLElement* g = child(collision, "geometry");
    const XMLElement* shape = g->FirstChildElement();
    if (!shape) fail(g, "link '" + link + "': <geometry> is empty (expected box, cylinder, sphere or mesh)");
    UrdfGeometry out;
    const std::string kind = shape->Name();
    const auto positive = [&](double v, const char* what) {
      if (!(v > 0)) fail(shape, "link '" + link + "': <" + kind + "> " + what + " must be > 0");
    };
    if (kind == "box") {
      const auto s = numbers(shape, "size", 3);
      out.box_size_m = Eigen::Vector3d(s[0], s[1], s[2]);
      for (double v : s) positive(v, "size");
    } else if (kind == "cylinder") {
      out.shape = UrdfShape::kCylinder;
      out.radius_m = number(shape, "radius");
      out.length_m = number(shape, "length");
      positive(out.radius_m, "radius");
      positive(out.length_m, "length");
    } else if (kind == "sphere") {
      out.shape = UrdfShape::kSphere;
      out.radius_m = number(shape, "radius");
      positive(out.radius_m, "radius");
    } else if (kind == "mesh") {
      out.shape = UrdfShape::kMesh;
      out.mesh_uri = text(shape, "filename");
      const auto scale = numbers(shape, "scale", 3, std::vector<double>{1, 1, 1});
      out.mesh_scale = Eigen::Vector3d(scale[0], scale[1], scale[2]);
      if ((out.mesh_scale.array() == 0).any()) fail(shape, "link '" + link + "': mesh scale must not be 0");
      out.mesh_file = mesh_file(shape, link, out.mesh_uri);
    } else {
      fail(shape, "link '" + link + "': unknown shape <" + kind + "> (URDF has box, cylinder, sphere and mesh)");
    }
    return out;
  }

  // The collision mesh's path, checked to be a file MuJoCo 2.2.2 reads: binary STL or OBJ (or its own MSH).
  std::string mesh_file(const XMLElement* mesh, const std::string& link, const std::string& uri) const {
    std::string path;
    try {
      path = resolve_package_uri(uri, dir_, package_path_);
    } catch (const std::invalid_argument& e) {
      fail(mesh, "link '" + link + "': " + e.what());
    }
    const std::string ext = lower(fs::path(path).extension().string());
    if (ext == ".dae")
      fail(mesh,
           "link '" + link + "': collision mesh '" + uri +
               "' is COLLADA (.dae); MuJoCo 2.2.2 reads STL and OBJ only: "
               "convert it (e.g. assimp export in.dae out.stl, or MeshLab) and name the STL or OBJ in <collision>");
    if (ext != ".stl" && ext != ".obj" && ext != ".msh")
      fail(mesh,
           "link '" + link + "': collision mesh '" + uri + "' is neither STL nor OBJ (the formats MuJoCo 2.2.2 reads)");
    if (ext == ".stl") {
      std::ifstream in(path, std::ios::binary);
      char header[84] = {};
      in.read(header, sizeof header);
      const auto size = fs::file_size(path);
      std::uint32_t faces = 0;
      std::memcpy(&faces, header + 80, sizeof faces);
      if (!in || faces < 1 || faces > 200000 || size != 84 + 50 * std::uintmax_t{faces})
        fail(mesh, "link '" + link + "': collision mesh " + path +
                       " is not a binary STL of 1 to 200000 triangles "
                       "(an ASCII STL?); MuJoCo 2.2.2 reads binary STL only: convert it (e.g. with MeshLab or assimp)");
    }
    return path;
  }

  UrdfLink link(const XMLElement* e, std::set<std::string>& dae_visuals) const {
    UrdfLink link;
    link.name = text(e, "name");
    link.line = e->GetLineNum();
    if (link.name.empty()) fail(e, "a <link> has an empty name");
    if (const XMLElement* in = e->FirstChildElement("inertial")) {
      UrdfInertial inertial;
      inertial.T_link_inertial = origin(in);
      inertial.mass_kg = number(child(in, "mass"), "value");
      const XMLElement* i = child(in, "inertia");
      const double ixx = number(i, "ixx", 0.0), iyy = number(i, "iyy", 0.0), izz = number(i, "izz", 0.0);
      const double ixy = number(i, "ixy", 0.0), ixz = number(i, "ixz", 0.0), iyz = number(i, "iyz", 0.0);
      inertial.inertia_kgm2 << ixx, ixy, ixz, ixy, iyy, iyz, ixz, iyz, izz;
      if (inertial.mass_kg < 0) fail(in, "link '" + link.name + "': mass must be >= 0");
      link.inertial = inertial;
    }
    for (const XMLElement* c = e->FirstChildElement("collision"); c; c = c->NextSiblingElement("collision"))
      link.collisions.push_back({origin(c), collision_geometry(c, link.name)});
    for (const XMLElement* v = e->FirstChildElement("visual"); v; v = v->NextSiblingElement("visual")) {
      const XMLElement* g = v->FirstChildElement("geometry");
      const XMLElement* mesh = g ? g->FirstChildElement("mesh") : nullptr;
      const char* uri = mesh ? mesh->Attribute("filename") : nullptr;
      if (uri && lower(fs::path(uri).extension().string()) == ".dae") dae_visuals.insert(link.name);
    }
    return link;
  }

  UrdfJoint joint(const XMLElement* e) const {
    UrdfJoint j;
    j.name = text(e, "name");
    j.line = e->GetLineNum();
    const std::string type = text(e, "type");
    try {
      j.type = parse_enum(type, kJointTypes, "joint type");
    } catch (const std::invalid_argument& error) {
      fail(e, "joint '" + j.name + "': " + error.what());
    }
    j.parent = text(child(e, "parent"), "link");
    j.child = text(child(e, "child"), "link");
    j.T_parent_joint = origin(e);
    if (const XMLElement* a = e->FirstChildElement("axis")) {
      const auto xyz = numbers(a, "xyz", 3, std::vector<double>{1, 0, 0});
      const Eigen::Vector3d axis(xyz[0], xyz[1], xyz[2]);
      if (axis.norm() < 1e-9) fail(a, "joint '" + j.name + "': the axis is zero");
      j.axis = axis.normalized();
    }
    if (const XMLElement* l = e->FirstChildElement("limit")) {
      if (l->Attribute("lower") || l->Attribute("upper")) {
        j.lower = number(l, "lower", 0.0);
        j.upper = number(l, "upper", 0.0);
        j.has_limits = j.lower < j.upper;  // as MuJoCo's reader: an empty range means no limits
      }
    }
    if (const XMLElement* d = e->FirstChildElement("dynamics")) {
      j.damping = number(d, "damping", 0.0);
      j.friction = number(d, "friction", 0.0);
    }
    return j;
  }

 private:
  std::string file_;
  std::vector<std::string> package_path_;
  std::string dir_;
};

// " (links, nearest first: a, b, ...)": every link, the names nearest to `name` first.
std::string links_nearest_first(const UrdfModel& model, const std::string& name) {
  std::vector<std::string> names;
  for (const auto& l : model.links) names.push_back(l.name);
  std::stable_sort(names.begin(), names.end(), [&](const std::string& a, const std::string& b) {
    return edit_distance(name, a) < edit_distance(name, b);
  });
  return " (links, nearest first: " + joined(names) + ")";
}

// Every link but one is exactly one joint's child, and every link hangs below that one (no loop).
void check_tree(UrdfModel& model) {
  std::map<std::string, const UrdfJoint*> parent_of;
  for (const auto& j : model.joints) {
    for (const std::string* end : {&j.parent, &j.child})
      if (!model.find_link(*end))
        throw std::invalid_argument(model.file + ":" + std::to_string(j.line) + ": joint '" + j.name + "': its " +
                                    (end == &j.parent ? "parent" : "child") + " link '" + *end +
                                    "' is not in the file" + links_nearest_first(model, *end));
    if (j.parent == j.child)
      throw std::invalid_argument(model.file + ":" + std::to_string(j.line) + ": joint '" + j.name + "' joins link '" +
                                  j.parent + "' to itself (a loop); its child must be another link");
    const auto [it, inserted] = parent_of.emplace(j.child, &j);
    if (!inserted)
      throw std::invalid_argument(model.file + ":" + std::to_string(j.line) + ": link '" + j.child +
                                  "' has two parents (joints '" + it->second->name + "' and '" + j.name +
                                  "'): URDF is a tree; remove one joint (a closed chain cannot be described)");
  }
  std::vector<std::string> roots;
  for (const auto& l : model.links)
    if (!parent_of.count(l.name)) roots.push_back(l.name);
  if (roots.size() > 1)
    throw std::invalid_argument(model.file + ": " + std::to_string(roots.size()) + " links have no parent (" +
                                joined(roots) +
                                "): join them to one tree (every link but the root is some joint's child)");
  std::set<std::string> reached(roots.begin(), roots.end());
  for (std::vector<std::string> next = roots; !next.empty();) {
    std::vector<std::string> below;
    for (const auto& j : model.joints)
      if (std::find(next.begin(), next.end(), j.parent) != next.end() && reached.insert(j.child).second)
        below.push_back(j.child);
    next = std::move(below);
  }
  for (const auto& l : model.links) {
    if (reached.count(l.name)) continue;
    // Not below the root: its parents lead round a loop. Follow them until a link repeats.
    std::vector<std::string> chain{l.name};
    for (;;) {
      const std::string parent = parent_of.at(chain.back())->parent;
      const auto seen = std::find(chain.begin(), chain.end(), parent) - chain.begin();
      chain.push_back(parent);
      if (seen + 1 < static_cast<std::ptrdiff_t>(chain.size())) {
        chain.erase(chain.begin(), chain.begin() + seen);
        break;
      }
    }
    throw std::invalid_argument(model.file + ":" + std::to_string(parent_of.at(chain.front())->line) +
                                ": the joints form a loop (" + joined(chain) +
                                ", each the parent of the one before): remove one of these joints");
  }
  model.root = roots.front();
  if (model.root == "world")
    throw std::invalid_argument(model.file +
                                ": the root link is 'world' (a robot fixed to the ground); a driving robot "
                                "needs a free root: remove the link 'world' and its joint");
}

}  // namespace

Eigen::Matrix3d rpy_to_matrix(const Eigen::Vector3d& rpy) {
  return (Eigen::AngleAxisd(rpy.z(), Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(rpy.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

double rest_position(const UrdfJoint& joint) {
  const bool limited =
      joint.has_limits && (joint.type == UrdfJointType::kRevolute || joint.type == UrdfJointType::kPrismatic);
  return limited ? std::clamp(0.0, joint.lower, joint.upper) : 0.0;
}

Eigen::Isometry3d T_parent_child(const UrdfJoint& joint, double position) {
  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  if (joint.type == UrdfJointType::kRevolute || joint.type == UrdfJointType::kContinuous)
    motion.linear() = Eigen::AngleAxisd(position, joint.axis).toRotationMatrix();
  else if (joint.type == UrdfJointType::kPrismatic) motion.translation() = position * joint.axis;
  return joint.T_parent_joint * motion;
}

const UrdfLink* UrdfModel::find_link(const std::string& name) const {
  for (const auto& l : links)
    if (l.name == name) return &l;
  return nullptr;
}

const UrdfJoint* UrdfModel::parent_joint(const std::string& link) const {
  for (const auto& j : joints)
    if (j.child == link) return &j;
  return nullptr;
}

std::string UrdfModel::unknown_link_message(const std::string& name) const {
  return file + ": no link named '" + name + "'" + links_nearest_first(*this, name);
}

Eigen::Isometry3d UrdfModel::T_root_link(const std::string& link) const {
  if (!find_link(link)) throw std::invalid_argument(unknown_link_message(link));
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  std::size_t depth = 0;
  for (const UrdfJoint* j = parent_joint(link); j; j = parent_joint(j->parent)) {
    T = T_parent_child(*j, rest_position(*j)) * T;
    if (++depth > joints.size())
      throw std::invalid_argument(file + ": the joints form a loop above link '" + link + "'");
  }
  return T;
}

UrdfModel parse_urdf(const std::string& text, const std::string& file, const std::vector<std::string>& package_path) {
  tinyxml2::XMLDocument doc;
  if (doc.Parse(text.data(), text.size()) != tinyxml2::XML_SUCCESS)
    throw std::invalid_argument(file + ":" + std::to_string(doc.ErrorLineNum()) + ": malformed XML: " + doc.ErrorStr());
  const Reader reader(file, package_path);
  const XMLElement* robot = doc.RootElement();
  if (!robot || std::string(robot->Name()) != "robot")
    reader.fail(
        robot,
        std::string("the root element is <") + (robot ? robot->Name() : "") +
            ">, expected <robot> (is this a URDF? a xacro file must be expanded first: xacro in.xacro > out.urdf)");
  UrdfModel model;
  model.file = file;
  model.name = robot->Attribute("name") ? robot->Attribute("name") : "";
  std::set<std::string> dae_visuals;
  for (const XMLElement* e = robot->FirstChildElement("link"); e; e = e->NextSiblingElement("link")) {
    UrdfLink link = reader.link(e, dae_visuals);
    if (model.find_link(link.name)) reader.fail(e, "two links are named '" + link.name + "'");
    model.links.push_back(std::move(link));
  }
  if (model.links.empty()) reader.fail(robot, "the robot has no <link>");
  for (const XMLElement* e = robot->FirstChildElement("joint"); e; e = e->NextSiblingElement("joint")) {
    UrdfJoint joint = reader.joint(e);
    for (const auto& other : model.joints)
      if (other.name == joint.name) reader.fail(e, "two joints are named '" + joint.name + "'");
    model.joints.push_back(std::move(joint));
  }
  check_tree(model);
  if (!dae_visuals.empty())
    model.notices.push_back("URDF " + file + ": visual DAE meshes skipped (links " +
                            joined({dae_visuals.begin(), dae_visuals.end()}) +
                            "): the bench uses collision geometry only, and MuJoCo 2.2.2 reads no DAE");
  return model;
}

UrdfModel load_urdf(const std::string& path, const std::vector<std::string>& package_path) {
  if (!fs::is_regular_file(path)) throw std::invalid_argument("URDF file not found: '" + path + "'");
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in && !in.eof()) throw std::invalid_argument("cannot read URDF file '" + path + "'");
  return parse_urdf(text.str(), path, package_path);
}

}  // namespace stvl::robot_description
