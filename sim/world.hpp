#pragma once
// A loaded MuJoCo world: owns mjModel and mjData. Invariant: after construction and after every
// step(), the kinematic quantities in data() (xpos, geom_xpos, site_xpos, ...) match time_s().
#include <memory>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>
#include <Eigen/Geometry>

namespace stvl::sim {

// Geom groups of the robot: 2 for its geoms (hidden from the depth renderer, skipped by ground truth), 3 for
// the robot geoms the cameras see (drawn, still skipped by ground truth: the robot is no obstacle).
constexpr int kRobotGeomGroup = 2;
constexpr int kRobotSeenGeomGroup = 3;

// A file MuJoCo reads from memory instead of disk. MuJoCo 2.2.2's virtual file system matches files by their base
// name, case-insensitively, wherever an <include> or a mesh names them.
struct VirtualFile {
  std::string name;  // a base name, e.g. "robot.xml"
  std::string text;
};

class World {
 public:
  // Throws std::runtime_error naming the path and quoting MuJoCo's error text.
  static World from_file(const std::string& path);
  // The world at `path` with `replacements` standing in for the files of their names (sim/urdf_robot.hpp gives a
  // generated robot.xml this way). Throws std::runtime_error as from_file.
  static World from_file(const std::string& path, const std::vector<VirtualFile>& replacements);
  // `base_dir` resolves <include file=...> and mesh files; empty means the current directory. `replacements` stand
  // in for the files of their names.
  static World from_string(const std::string& xml, const std::string& base_dir = "",
                           const std::vector<VirtualFile>& replacements = {});

  World(World&&) noexcept;
  World& operator=(World&&) noexcept;
  World(const World&) = delete;
  World& operator=(const World&) = delete;
  ~World();

  const mjModel* model() const { return model_.get(); }
  // Run-time edits of model parameters (site poses, ...). Call forward() afterwards.
  mjModel* mutable_model() { return model_.get(); }
  mjData* data() { return data_.get(); }
  const mjData* data() const { return data_.get(); }

  double time_s() const { return data_->time; }
  double timestep_s() const { return model_->opt.timestep; }
  const std::string& source() const { return source_; }

  // Advances one physics step with the controls already in data()->ctrl (mj_step2 then mj_step1).
  void step();
  // Recomputes everything from qpos/qvel/mocap (mj_forward), e.g. after editing the state.
  void forward();

  // A world of its own with a copy of this one's model (mj_copyModel) and state (copy_state_from): a snapshot that
  // copy_state_from() keeps in step with this world while this one moves on (the pipeline running ahead).
  World copy() const;
  // Takes `other`'s whole state (as mj_copyData: time, positions, poses, contacts; not the scratch stack).
  // Throws std::invalid_argument when other's model differs in its sizes.
  void copy_state_from(const World& other);

  // x/y extent (world frame, m) of the geoms outside groups 2 and 3 (the robot's) at their current poses: finite
  // planes as their rectangles, other geoms as their bounding spheres; infinite planes are left out. Empty
  // when there is no such geom.
  Eigen::AlignedBox2d extent_xy() const;

  // Name lookups; throw std::invalid_argument naming the missing object.
  int body_id(const std::string& name) const;
  int site_id(const std::string& name) const;
  int joint_id(const std::string& name) const;
  int actuator_id(const std::string& name) const;
  int geom_id(const std::string& name) const;
  int camera_id(const std::string& name) const;
  std::string body_name(int body_id) const;

  // Lets the depth cameras see these robot geoms (group 2 -> 3; see kRobotSeenGeomGroup). Throws
  // std::invalid_argument for a name that is no geom or a geom that is not the robot's (not in group 2 or 3).
  void show_robot_geoms_to_cameras(const std::vector<std::string>& geom_names);

 private:
  struct ModelDeleter {
    void operator()(mjModel* m) const { mj_deleteModel(m); }
  };
  struct DataDeleter {
    void operator()(mjData* d) const { mj_deleteData(d); }
  };
  World(mjModel* model, std::string source);
  int id_of(int type, const std::string& name, const char* what) const;

  std::unique_ptr<mjModel, ModelDeleter> model_;
  std::unique_ptr<mjData, DataDeleter> data_;
  std::string source_;
};

}  // namespace stvl::sim
