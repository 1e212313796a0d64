#include "tests/support/fixture.hpp"

#include <unistd.h>

#include <array>
#include <atomic>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace stvl::test {
namespace {

std::atomic<int> expecting_warnings{0};  // live ExpectMujocoWarning objects
std::atomic<int> warnings_seen{0};       // warnings counted while one lives

void on_warning(const char* message) {
  if (expecting_warnings.load() > 0) {
    ++warnings_seen;
    return;
  }
  ADD_FAILURE() << "MuJoCo warning: " << message;
}

}  // namespace

std::string worlds_dir() { return std::string(STVL_SOURCE_DIR) + "/worlds"; }

MjModelPtr load_model_from_string(const std::string& xml, const std::string& base_dir) {
  const std::filesystem::path dir =
      base_dir.empty() ? std::filesystem::current_path() : std::filesystem::path(base_dir);
  const std::string name = (dir / "__stvl_test_world__.xml").string();
  auto vfs = std::make_unique<mjVFS>();  // about 2 MB: heap only
  mj_defaultVFS(vfs.get());
  if (mj_makeEmptyFileVFS(vfs.get(), name.c_str(), static_cast<int>(xml.size())) != 0)
    throw std::runtime_error("test world: cannot make a virtual file for the MJCF text");
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), name.c_str())], xml.data(), xml.size());
  std::array<char, 1024> error{};
  MjModelPtr model(mj_loadXML(name.c_str(), vfs.get(), error.data(), static_cast<int>(error.size())));
  mj_deleteVFS(vfs.get());
  if (!model) throw std::runtime_error(std::string("test world: ") + error.data());
  return model;
}

MjWorld::MjWorld(const std::string& xml, const std::string& base_dir)
    : model_(load_model_from_string(xml, base_dir)), data_(mj_makeData(model_.get())) {
  if (!data_) throw std::runtime_error("test world: mj_makeData failed");
  mj_forward(model_.get(), data_.get());
}

WorldFile::WorldFile(const std::string& name, const std::string& xml) {
  static std::atomic<int> serial{0};
  dir_ = std::filesystem::temp_directory_path() /
         ("stvl_world_" + std::to_string(::getpid()) + "_" + std::to_string(serial++));
  std::filesystem::remove_all(dir_);
  std::filesystem::create_directories(dir_);
  std::filesystem::copy_file(worlds_dir() + "/robot.xml", dir_ / "robot.xml");
  path_ = dir_ / name;
  std::ofstream(path_) << xml;
}

WorldFile::~WorldFile() {
  std::error_code ignored;
  std::filesystem::remove_all(dir_, ignored);
}

Eigen::Isometry3d looking_along_x(const Eigen::Vector3d& position_W, const Eigen::Matrix3d& extra) {
  Eigen::Matrix3d R;
  R << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R * extra;
  T.translation() = position_W;
  return T;
}

MujocoWarningGuard::MujocoWarningGuard() : previous_(mju_user_warning) { mju_user_warning = &on_warning; }
MujocoWarningGuard::~MujocoWarningGuard() { mju_user_warning = previous_; }

ExpectMujocoWarning::ExpectMujocoWarning() : before_(warnings_seen.load()) { ++expecting_warnings; }
ExpectMujocoWarning::~ExpectMujocoWarning() {
  --expecting_warnings;
  if (count() == 0) ADD_FAILURE() << "expected a MuJoCo warning, none came";
}
int ExpectMujocoWarning::count() const { return warnings_seen.load() - before_; }

}  // namespace stvl::test
