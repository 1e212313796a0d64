#pragma once
// Tiny URDFs for the tests of robot_description/ and sim/urdf_robot, and a temporary folder to write them (and
// meshes) into.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

namespace stvl::test {

// A fresh folder under the system's temporary one, removed with the object.
class TempFolder {
 public:
  TempFolder() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = std::filesystem::temp_directory_path() /
            ("stvl_urdf_" + std::string(info ? info->name() : "test") + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~TempFolder() { std::filesystem::remove_all(path_); }
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;
  // Writes `text` to `relative` (folders created) and returns its path.
  std::string write(const std::string& relative, const std::string& text) const {
    const auto file = path_ / relative;
    std::filesystem::create_directories(file.parent_path());
    std::ofstream(file, std::ios::binary) << text;
    return file.string();
  }
  std::string path() const { return path_.string(); }

 private:
  std::filesystem::path path_;
};

// tiny_bot: a box base (base_link on the wheel axle, box 0.4 x 0.3 x 0.1 m from z 0 to 0.1), two cylinder wheels
// of radius 0.06 m at y +-0.18 on continuous joints (the left one's axis +y, the right one's -y, as some URDFs
// write them), a fixed caster sphere, and camera_link 0.3 m above base_link, 0.15 m ahead, with
// camera_depth_optical_frame on a fixed joint rotated rpy (-pi/2, 0, -pi/2). The base's mass (5 kg) sits 0.05 m
// behind the axle, between the wheels and the caster. `inertials`: false leaves every
// <inertial> out (URDF's massless links). `extra` goes in before </robot>.
inline std::string tiny_bot_urdf(bool inertials = true, const std::string& extra = "") {
  const auto inertial = [&](double mass, double i, const std::string& origin = "0 0 0") {
    if (!inertials) return std::string();
    const std::string v = std::to_string(i);
    return "<inertial><origin xyz=\"" + origin + "\"/><mass value=\"" + std::to_string(mass) + "\"/><inertia ixx=\"" +
           v + "\" ixy=\"0\" ixz=\"0\" iyy=\"" + v + "\" iyz=\"0\" izz=\"" + v + "\"/></inertial>";
  };
  const auto wheel = [&](const std::string& side, double y, const std::string& axis) {
    return "<joint name=\"" + side + "_wheel_joint\" type=\"continuous\"><parent link=\"base_link\"/><child link=\"" +
           side + "_wheel\"/><origin xyz=\"0 " + std::to_string(y) + " 0\"/><axis xyz=\"" + axis +
           "\"/></joint>\n"
           "<link name=\"" +
           side +
           "_wheel\"><collision><origin rpy=\"1.5707963267948966 0 0\"/><geometry><cylinder "
           "radius=\"0.06\" length=\"0.04\"/></geometry></collision>" +
           inertial(0.3, 0.0006) + "</link>\n";
  };
  return "<?xml version=\"1.0\"?>\n<robot name=\"tiny_bot\">\n"
         "<link name=\"base_link\"><collision><origin xyz=\"0 0 0.05\"/><geometry><box size=\"0.4 0.3 "
         "0.1\"/></geometry>"
         "</collision>" +
         inertial(5.0, 0.08, "-0.05 0 0.05") + "</link>\n" + wheel("left", 0.18, "0 1 0") +
         wheel("right", -0.18, "0 -1 0") +
         "<joint name=\"caster_joint\" type=\"fixed\"><parent link=\"base_link\"/><child link=\"caster\"/>"
         "<origin xyz=\"-0.15 0 -0.03\"/></joint>\n"
         "<link name=\"caster\"><collision><geometry><sphere radius=\"0.03\"/></geometry></collision>" +
         inertial(0.05, 0.00002) +
         "</link>\n"
         "<joint name=\"camera_joint\" type=\"fixed\"><parent link=\"base_link\"/><child link=\"camera_link\"/>"
         "<origin xyz=\"0.15 0 0.3\"/></joint>\n<link name=\"camera_link\"/>\n"
         "<joint name=\"camera_optical_joint\" type=\"fixed\"><parent link=\"camera_link\"/>"
         "<child link=\"camera_depth_optical_frame\"/><origin rpy=\"-1.5707963267948966 0 "
         "-1.5707963267948966\"/></joint>\n"
         "<link name=\"camera_depth_optical_frame\"/>\n" +
         extra + "</robot>\n";
}

// A world of the tests: a 40 x 40 m floor and <include file="robot.xml"/>, timestep 2 ms.
inline constexpr const char* kUrdfFloorWorld = R"(<mujoco>
  <compiler autolimits="true"/>
  <option timestep="0.002"/>
  <include file="robot.xml"/>
  <worldbody><geom name="floor" type="plane" size="20 20 0.1"/></worldbody>
</mujoco>
)";

}  // namespace stvl::test
