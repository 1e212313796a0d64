#pragma once
// The tiny-world fixture shared by the tests of sim/, sensors/, pipeline/ and evaluation/ (after MuJoCo's own
// test/fixture.h): models and data owned by std::unique_ptr with a deleter, inline MJCF compiled from a string,
// the few worlds several tests share, and a MuJoCo warning failing the test that is running.
//
// Every test binary that includes this header fails any test during which MuJoCo calls mju_user_warning (a gtest
// Environment installs the handler for the whole run); fixtures may also derive from MujocoTest, which installs it
// around each test. A test that expects a warning says so with an ExpectMujocoWarning in its scope.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <Eigen/Geometry>

#include <filesystem>
#include <memory>
#include <string>

namespace stvl::test {

struct MjModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct MjDataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using MjModelPtr = std::unique_ptr<mjModel, MjModelDeleter>;
using MjDataPtr = std::unique_ptr<mjData, MjDataDeleter>;

// The shipped worlds' folder (worlds/ of this checkout): <include file="robot.xml"/> resolves there.
std::string worlds_dir();

// Compiles MJCF text through MuJoCo's virtual file system (no file is written); relative <include>s and mesh
// files resolve against base_dir on disk (empty: the current directory). Throws std::runtime_error quoting
// MuJoCo's error text. Never null.
MjModelPtr load_model_from_string(const std::string& xml, const std::string& base_dir = "");

// A model compiled from a string and its data after mj_forward.
class MjWorld {
 public:
  explicit MjWorld(const std::string& xml, const std::string& base_dir = "");
  mjModel* model() const { return model_.get(); }
  mjData* data() const { return data_.get(); }

 private:
  MjModelPtr model_;
  MjDataPtr data_;
};

// The MJCF text written to `name` in a fresh temporary folder beside a copy of the shipped robot.xml, for code
// that takes a world file's path (PipelineConfig::world_path); the folder goes with the object.
class WorldFile {
 public:
  WorldFile(const std::string& name, const std::string& xml);
  ~WorldFile();
  WorldFile(const WorldFile&) = delete;
  WorldFile& operator=(const WorldFile&) = delete;
  std::string path() const { return path_.string(); }

 private:
  std::filesystem::path dir_, path_;
};

// --- The shared worlds (load those with <include file="robot.xml"/> with base_dir worlds_dir()) ---------------

// The shipped robot on an empty 60 x 60 m floor, timestep 2 ms.
inline constexpr const char* kFlatWorld = R"(
<mujoco>
  <compiler autolimits="true"/>
  <option timestep="0.002"/>
  <include file="robot.xml"/>
  <worldbody>
    <geom name="floor" type="plane" size="30 30 0.1"/>
  </worldbody>
</mujoco>)";

// The shipped robot on a 12 x 12 m floor facing a wall 2.5 m ahead (body "wall": x 2.5..2.7, y -2..2,
// z 0..1.5) and a second one behind it (body "back_wall": x -2.7..-2.5).
inline constexpr const char* kRobotBetweenWallsWorld = R"(
<mujoco>
  <compiler autolimits="true"/>
  <option timestep="0.002"/>
  <include file="robot.xml"/>
  <worldbody>
    <geom name="floor" type="plane" size="6 6 0.1"/>
    <body name="wall" pos="2.6 0 0.75"><geom type="box" size="0.1 2 0.75"/></body>
    <body name="back_wall" pos="-2.6 0 0.75"><geom type="box" size="0.1 2 0.75"/></body>
  </worldbody>
</mujoco>)";

// A box at x 2.05..2.65 m, |y| <= 0.25 m, z 0.15..0.65 m (body "box"); no floor. At 0.1 m voxels its front face
// is the layer x = 20 (y keys -3..2, z keys 1..6).
inline constexpr const char* kBoxWorld = R"(
<mujoco>
  <worldbody>
    <body name="box" pos="2.35 0 0.4"><geom type="box" size="0.3 0.25 0.25"/></body>
  </worldbody>
</mujoco>)";

// kBoxWorld and a mocap cart, a 0.2 m cube at (1.0, 0, 0.4) (body "cart", mocap index 0).
inline constexpr const char* kBoxAndCartWorld = R"(
<mujoco>
  <worldbody>
    <body name="box" pos="2.35 0 0.4"><geom type="box" size="0.3 0.25 0.25"/></body>
    <body name="cart" mocap="true" pos="1.0 0 0.4"><geom type="box" size="0.1 0.1 0.1"/></body>
  </worldbody>
</mujoco>)";

// Optical frame looking along world +x from position_W (optical x right = world -y, y down = world -z), then
// rotated by `extra` about the optical axes.
Eigen::Isometry3d looking_along_x(const Eigen::Vector3d& position_W,
                                  const Eigen::Matrix3d& extra = Eigen::Matrix3d::Identity());

// --- MuJoCo warnings fail the test --------------------------------------------------------------------------

// Installs a mju_user_warning handler that ADD_FAILURE()s with MuJoCo's text (or, inside an ExpectMujocoWarning,
// counts it); restores the previous handler when it goes.
class MujocoWarningGuard {
 public:
  MujocoWarningGuard();
  ~MujocoWarningGuard();
  MujocoWarningGuard(const MujocoWarningGuard&) = delete;
  MujocoWarningGuard& operator=(const MujocoWarningGuard&) = delete;

 private:
  void (*previous_)(const char*);
};

// While one lives, MuJoCo warnings are counted instead of failing the test; it fails the test when it goes
// without having seen one.
class ExpectMujocoWarning {
 public:
  ExpectMujocoWarning();
  ~ExpectMujocoWarning();
  ExpectMujocoWarning(const ExpectMujocoWarning&) = delete;
  ExpectMujocoWarning& operator=(const ExpectMujocoWarning&) = delete;
  int count() const;

 private:
  int before_;
};

// Base of test fixtures on MuJoCo: the warning guard around every test (SetUp to TearDown).
class MujocoTest : public ::testing::Test {
 protected:
  void SetUp() override { guard_ = std::make_unique<MujocoWarningGuard>(); }
  void TearDown() override { guard_.reset(); }

 private:
  std::unique_ptr<MujocoWarningGuard> guard_;
};

// The same for parameterized fixtures.
template <class T>
class MujocoTestWithParam : public ::testing::TestWithParam<T> {
 protected:
  void SetUp() override { guard_ = std::make_unique<MujocoWarningGuard>(); }
  void TearDown() override { guard_.reset(); }

 private:
  std::unique_ptr<MujocoWarningGuard> guard_;
};

// The guard over a whole test binary; registered once by this header.
class MujocoWarningsFailTests : public ::testing::Environment {
 public:
  void SetUp() override { guard_ = std::make_unique<MujocoWarningGuard>(); }
  void TearDown() override { guard_.reset(); }

 private:
  std::unique_ptr<MujocoWarningGuard> guard_;
};
inline ::testing::Environment* const kMujocoWarningsFailTests =
    ::testing::AddGlobalTestEnvironment(new MujocoWarningsFailTests);

}  // namespace stvl::test
