#include "sim/world.hpp"

#include <array>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <sstream>
#include <stdexcept>

#include "common/markup.hpp"

namespace stvl::sim {
namespace {

constexpr int kErrorSize = 1024;
// More static body pairs than this are left to the contact filter: the exclusion list is walked every step.
constexpr std::size_t kMaxStaticExcludes = 20000;

std::string trimmed(const char* text) {
  std::string s(text);
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  for (char& c : s)
    if (c == '\n') c = ' ';
  return s;
}

// Compiles `name` from a virtual file system holding `files`; null with MuJoCo's message in `error` on failure.
// mjVFS is about 2 MB: heap only.
mjModel* load_with_vfs(const std::string& name, const std::vector<VirtualFile>& files,
                       std::array<char, kErrorSize>& error) {
  auto vfs = std::make_unique<mjVFS>();
  mj_defaultVFS(vfs.get());
  for (const auto& file : files) {
    if (file.text.empty() ||
        mj_makeEmptyFileVFS(vfs.get(), file.name.c_str(), static_cast<int>(file.text.size())) != 0) {
      mj_deleteVFS(vfs.get());
      throw std::runtime_error("cannot create virtual file '" + file.name + "' for world '" + name + "'");
    }
    std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), file.name.c_str())], file.text.data(), file.text.size());
  }
  mjModel* model = mj_loadXML(name.c_str(), vfs.get(), error.data(), kErrorSize);
  mj_deleteVFS(vfs.get());
  return model;
}

// The bodies welded to the world (body_weldid 0: the world body, static bodies, mocap bodies) with geoms, as
// <exclude> pairs. MuJoCo 2.2.2's broadphase pairs such bodies whenever their boxes overlap (a building's walls body
// overlaps every piece of furniture) and its contact filter then rejects every one of their geom pairs (same weld
// body), each step; excluded, mj_collision skips those pairs whole. The contacts are the same, since only pairs that
// never make one are skipped. Empty where nothing is to gain or the model could differ otherwise: collision from
// predefined pairs only, or no actuator (the compiler's fusestatic, which any <exclude> turns off, can then have
// run). Pairs are kept to those whose geoms' bounding spheres could overlap in any frame the broadphase aligns its
// boxes with (centre distance <= sqrt(3) x the sum of radii); unnamed bodies cannot be named and stay as they are.
std::string static_pair_excludes(const mjModel* m) {
  if (m->nu == 0 || m->opt.collision == mjCOL_PAIR) return {};
  mjData* d = mj_makeData(m);
  if (!d) return {};
  mj_kinematics(m, d);
  struct Static {
    int body;
    std::string name;
    Eigen::Vector3d centre;
    double radius;  // infinite for the world body (planes: every body pairs with it)
  };
  std::vector<Static> bodies;
  for (int b = 0; b < m->nbody; ++b) {
    if (m->body_weldid[b] != 0 || m->body_geomnum[b] == 0) continue;
    const char* name = mj_id2name(m, mjOBJ_BODY, b);
    if (!name || !*name) continue;
    Eigen::AlignedBox3d box;
    for (int g = m->body_geomadr[b]; g < m->body_geomadr[b] + m->body_geomnum[b]; ++g) {
      const double r = m->geom_rbound[g] + m->geom_margin[g];
      const Eigen::Vector3d c(d->geom_xpos[3 * g], d->geom_xpos[3 * g + 1], d->geom_xpos[3 * g + 2]);
      box.extend(c - Eigen::Vector3d::Constant(r));
      box.extend(c + Eigen::Vector3d::Constant(r));
    }
    const bool unbounded = b == 0 || !box.sizes().allFinite();
    bodies.push_back(
        {b, name, box.center(), unbounded ? std::numeric_limits<double>::infinity() : 0.5 * box.sizes().norm()});
  }
  mj_deleteData(d);
  std::set<int> excluded(m->exclude_signature, m->exclude_signature + m->nexclude);
  std::string xml;
  std::size_t pairs = 0;
  for (std::size_t i = 0; i < bodies.size(); ++i)
    for (std::size_t j = i + 1; j < bodies.size(); ++j) {
      const Static &a = bodies[i], &b = bodies[j];
      const bool near = !std::isfinite(a.radius) || !std::isfinite(b.radius) ||
                        (a.centre - b.centre).norm() <= std::sqrt(3.0) * (a.radius + b.radius);
      if (!near || excluded.count(((a.body + 1) << 16) + b.body + 1)) continue;
      xml += "<exclude body1=\"" + xml_escape(a.name) + "\" body2=\"" + xml_escape(b.name) + "\"/>\n";
      if (++pairs > kMaxStaticExcludes) return {};
    }
  return pairs == 0 ? std::string() : "<contact>\n" + xml + "</contact>\n";
}

// `model`, compiled from `files` (the top-level file first, named by name's base name), or the same world compiled
// again with static_pair_excludes() added to its top-level file (`model` then freed): the same bodies, geoms and
// degrees of freedom, a faster collision step. Where the second compile fails or differs, `model` as it is.
mjModel* with_static_pairs_excluded(mjModel* model, const std::string& name, std::vector<VirtualFile> files) {
  const std::string excludes = static_pair_excludes(model);
  std::string& top = files.front().text;
  const std::size_t end = top.rfind("</mujoco>");
  if (excludes.empty() || end == std::string::npos) return model;
  top.insert(end, excludes);
  std::array<char, kErrorSize> error{};
  mjModel* faster = nullptr;
  try {
    faster = load_with_vfs(name, files, error);
  } catch (const std::exception&) {
    return model;
  }
  if (!faster) return model;
  if (faster->nbody != model->nbody || faster->ngeom != model->ngeom || faster->nq != model->nq ||
      faster->nv != model->nv || faster->nu != model->nu || faster->nbuffer < model->nbuffer) {
    mj_deleteModel(faster);
    return model;
  }
  mj_deleteModel(model);
  return faster;
}

std::string file_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

World::World(mjModel* model, std::string source)
    : model_(model), data_(mj_makeData(model)), source_(std::move(source)) {
  if (!data_) throw std::runtime_error("mj_makeData failed for world '" + source_ + "'");
  mj_forward(model_.get(), data_.get());
}

World World::copy() const {
  mjModel* model = mj_copyModel(nullptr, model_.get());
  if (!model) throw std::runtime_error("mj_copyModel failed for world '" + source_ + "'");
  World world(model, source_);
  world.copy_state_from(*this);
  return world;
}

void World::copy_state_from(const World& other) {
  const mjModel* m = model_.get();
  const mjModel* o = other.model_.get();
  if (m->nbuffer != o->nbuffer || m->nstack != o->nstack || m->ngeom != o->ngeom || m->nbody != o->nbody)
    throw std::invalid_argument("World::copy_state_from: '" + other.source_ + "' has another model than '" + source_ +
                                "'");
  // mj_copyData without its stack: every field before `buffer` is a size, a statistic or a scalar of the state
  // (time, contact and constraint counts), every field after it points into the buffer at offsets the model fixes,
  // alike in both; the buffer holds the whole state, and the stack (10 MB by default) is scratch, free between
  // steps.
  mjData* d = data_.get();
  const mjData* s = other.data_.get();
  std::memcpy(static_cast<void*>(d), static_cast<const void*>(s), offsetof(mjData, buffer));
  std::memcpy(d->buffer, s->buffer, static_cast<std::size_t>(m->nbuffer));
}

World::World(World&&) noexcept = default;
World& World::operator=(World&&) noexcept = default;
World::~World() = default;

World World::from_file(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw std::runtime_error("world file not found: '" + path + "'");
  }
  std::array<char, kErrorSize> error{};
  mjModel* model = mj_loadXML(path.c_str(), nullptr, error.data(), kErrorSize);
  if (!model) {
    throw std::runtime_error("cannot load world '" + path + "': " + trimmed(error.data()));
  }
  model = with_static_pairs_excluded(model, path, {{std::filesystem::path(path).filename().string(), file_text(path)}});
  return World(model, path);
}

World World::from_file(const std::string& path, const std::vector<VirtualFile>& replacements) {
  if (!std::filesystem::is_regular_file(path)) throw std::runtime_error("world file not found: '" + path + "'");
  std::vector<VirtualFile> files{{std::filesystem::path(path).filename().string(), file_text(path)}};
  files.insert(files.end(), replacements.begin(), replacements.end());
  std::array<char, kErrorSize> error{};
  mjModel* model = load_with_vfs(path, files, error);
  if (!model) throw std::runtime_error("cannot load world '" + path + "': " + trimmed(error.data()));
  return World(with_static_pairs_excluded(model, path, files), path);
}

Eigen::AlignedBox2d World::extent_xy() const {
  Eigen::AlignedBox2d extent;
  const mjModel* m = model_.get();
  for (int g = 0; g < m->ngeom; ++g) {
    if (m->geom_group[g] == kRobotGeomGroup || m->geom_group[g] == kRobotSeenGeomGroup) continue;
    const Eigen::Vector2d centre(data_->geom_xpos[3 * g], data_->geom_xpos[3 * g + 1]);
    if (m->geom_type[g] == mjGEOM_PLANE) {
      const double hx = m->geom_size[3 * g], hy = m->geom_size[3 * g + 1];
      if (hx <= 0 || hy <= 0) continue;            // infinite
      const double* R = data_->geom_xmat + 9 * g;  // row-major
      for (const double sx : {-hx, hx})
        for (const double sy : {-hy, hy})
          extent.extend(centre + Eigen::Vector2d(R[0] * sx + R[1] * sy, R[3] * sx + R[4] * sy));
    } else {
      const double r = m->geom_rbound[g];
      extent.extend(centre - Eigen::Vector2d(r, r));
      extent.extend(centre + Eigen::Vector2d(r, r));
    }
  }
  return extent;
}

World World::from_string(const std::string& xml, const std::string& base_dir,
                         const std::vector<VirtualFile>& replacements) {
  if (xml.empty()) throw std::invalid_argument("world XML string is empty");
  if (!base_dir.empty() && !std::filesystem::is_directory(base_dir)) {
    throw std::runtime_error("world base directory not found: '" + base_dir + "'");
  }
  // The string lives in MuJoCo's virtual file system under a name inside base_dir, so that
  // relative <include>s resolve against base_dir on disk.
  const std::filesystem::path dir =
      base_dir.empty() ? std::filesystem::current_path() : std::filesystem::path(base_dir);
  const std::string name = (dir / "__stvl_inline_world__.xml").string();
  std::array<char, kErrorSize> error{};
  std::vector<VirtualFile> files{{"__stvl_inline_world__.xml", xml}};
  files.insert(files.end(), replacements.begin(), replacements.end());
  mjModel* model = load_with_vfs(name, files, error);
  const std::string source = "<xml string, base dir '" + dir.string() + "'>";
  if (!model) throw std::runtime_error("cannot load world " + source + ": " + trimmed(error.data()));
  return World(with_static_pairs_excluded(model, name, files), source);
}

void World::step() {
  mj_step2(model_.get(), data_.get());
  mj_step1(model_.get(), data_.get());
}

void World::forward() { mj_forward(model_.get(), data_.get()); }

int World::id_of(int type, const std::string& name, const char* what) const {
  const int id = mj_name2id(model_.get(), type, name.c_str());
  if (id < 0) {
    throw std::invalid_argument(std::string("no ") + what + " named '" + name + "' in world '" + source_ + "'");
  }
  return id;
}

int World::body_id(const std::string& name) const { return id_of(mjOBJ_BODY, name, "body"); }
int World::site_id(const std::string& name) const { return id_of(mjOBJ_SITE, name, "site"); }
int World::joint_id(const std::string& name) const { return id_of(mjOBJ_JOINT, name, "joint"); }
int World::actuator_id(const std::string& name) const { return id_of(mjOBJ_ACTUATOR, name, "actuator"); }
int World::geom_id(const std::string& name) const { return id_of(mjOBJ_GEOM, name, "geom"); }
int World::camera_id(const std::string& name) const { return id_of(mjOBJ_CAMERA, name, "camera"); }

std::string World::body_name(int body_id) const {
  if (body_id < 0 || body_id >= model_->nbody) {
    throw std::invalid_argument("body id " + std::to_string(body_id) + " out of range");
  }
  const char* name = mj_id2name(model_.get(), mjOBJ_BODY, body_id);
  return name ? std::string(name) : "body_" + std::to_string(body_id);
}

void World::show_robot_geoms_to_cameras(const std::vector<std::string>& geom_names) {
  for (const auto& name : geom_names) {
    const int g = geom_id(name);
    int& group = model_->geom_group[g];
    if (group != kRobotGeomGroup && group != kRobotSeenGeomGroup)
      throw std::invalid_argument("geom '" + name + "' is not the robot's (group " + std::to_string(group) +
                                  ", the robot's geoms are in group 2)");
    group = kRobotSeenGeomGroup;
  }
}

}  // namespace stvl::sim
