// robot_description/urdf_model.hpp and robot_description/package_path.hpp: reading a URDF, resolving its meshes,
// and its bad inputs.
#include <gtest/gtest.h>

#include <cmath>

#include "robot_description/package_path.hpp"
#include "robot_description/urdf_model.hpp"
#include "tests/robot_description/urdf_texts.hpp"
#include "tests/support/invalid_argument.hpp"

namespace stvl::robot_description {
namespace {

using test::invalid_argument_of;
using test::TempFolder;
using test::tiny_bot_urdf;

constexpr const char* kObjCube =
    "v -0.1 -0.1 0\nv 0.1 -0.1 0\nv 0.1 0.1 0\nv -0.1 0.1 0\n"
    "v -0.1 -0.1 0.2\nv 0.1 -0.1 0.2\nv 0.1 0.1 0.2\nv -0.1 0.1 0.2\n"
    "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\nf 2 3 7\nf 2 7 6\n"
    "f 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n";

std::string with_mesh(const std::string& uri) {
  return tiny_bot_urdf(true, "<link name=\"shell\"><collision><geometry><mesh filename=\"" + uri +
                                 "\"/></geometry></collision></link><joint name=\"shell_joint\" type=\"fixed\">"
                                 "<parent link=\"base_link\"/><child link=\"shell\"/></joint>\n");
}

TEST(UrdfModel, ReadsTheTreeAndItsTransforms) {
  const UrdfModel urdf = parse_urdf(tiny_bot_urdf(), "tiny.urdf", {});
  EXPECT_EQ(urdf.name, "tiny_bot");
  EXPECT_EQ(urdf.root, "base_link");
  EXPECT_EQ(urdf.links.size(), 6u);
  EXPECT_EQ(urdf.joints.size(), 5u);
  ASSERT_TRUE(urdf.find_link("left_wheel"));
  EXPECT_EQ(urdf.find_link("left_wheel")->collisions.front().geometry.shape, UrdfShape::kCylinder);
  EXPECT_DOUBLE_EQ(urdf.find_link("left_wheel")->collisions.front().geometry.radius_m, 0.06);
  EXPECT_NEAR(urdf.find_link("base_link")->inertial->mass_kg, 5.0, 1e-12);
  // The optical frame's chain: translation from camera_joint, the rotation of REP-103's optical frame.
  const Eigen::Isometry3d T = urdf.T_root_link("camera_depth_optical_frame");
  EXPECT_TRUE(T.translation().isApprox(Eigen::Vector3d(0.15, 0, 0.3), 1e-12));
  Eigen::Matrix3d R_link_optical;  // columns: optical x, y, z in camera_link (DiffDriveRobot's)
  R_link_optical << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  EXPECT_TRUE(T.linear().isApprox(R_link_optical, 1e-12)) << T.linear();
  EXPECT_TRUE(urdf.notices.empty());
}

TEST(UrdfModel, UnknownLinkListsTheLinksNearestFirst) {
  const UrdfModel urdf = parse_urdf(tiny_bot_urdf(), "tiny.urdf", {});
  const std::string message = invalid_argument_of([&] { urdf.T_root_link("camera_depth_optical"); });
  EXPECT_NE(message.find("tiny.urdf: no link named 'camera_depth_optical' (links, nearest first: "
                         "camera_depth_optical_frame, camera_link"),
            std::string::npos)
      << message;
}

TEST(UrdfModel, HeldJointsRestInsideTheirLimits) {
  const UrdfModel urdf = parse_urdf(
      tiny_bot_urdf(true,
                    "<joint name=\"tilt\" type=\"revolute\"><parent link=\"camera_link\"/><child link=\"tilted\"/>"
                    "<axis xyz=\"0 1 0\"/><limit lower=\"0.2\" upper=\"0.5\" effort=\"1\" velocity=\"1\"/></joint>"
                    "<link name=\"tilted\"/>"),
      "tiny.urdf", {});
  const Eigen::Matrix3d R = urdf.T_root_link("tilted").linear();
  EXPECT_TRUE(R.isApprox(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()).toRotationMatrix(), 1e-12));
}

TEST(UrdfModel, ResolvesPackageUrisAgainstThePackagePath) {
  TempFolder dir;
  const std::string mesh = dir.write("src/my_robot_description/meshes/shell.obj", kObjCube);
  const std::string expected = std::filesystem::path(mesh).lexically_normal().string();
  // The entry holds the package folder, or is the package folder itself.
  for (const std::string& entry : {dir.path() + "/src", dir.path() + "/src/my_robot_description/"}) {
    const UrdfModel urdf = parse_urdf(with_mesh("package://my_robot_description/meshes/shell.obj"),
                                      dir.path() + "/robot.urdf", {"/nonexistent", entry});
    EXPECT_EQ(urdf.find_link("shell")->collisions.front().geometry.mesh_file, expected) << entry;
  }
  // file:// and a path relative to the URDF's folder.
  EXPECT_EQ(resolve_package_uri("file://" + mesh, "/elsewhere", {}), expected);
  EXPECT_EQ(resolve_package_uri("src/my_robot_description/meshes/shell.obj", dir.path(), {}), expected);
}

TEST(UrdfModel, PackageErrorsNameWhatWasSearched) {
  TempFolder dir;
  dir.write("pkgs/bot/meshes/other.obj", kObjCube);
  std::string message =
      invalid_argument_of([&] { parse_urdf(with_mesh("package://bot/meshes/shell.obj"), "r.urdf", {}); });
  EXPECT_NE(message.find("names package 'bot' but robot.package_path is empty"), std::string::npos) << message;
  EXPECT_EQ(message.rfind("r.urdf:", 0), 0u) << message;
  message = invalid_argument_of(
      [&] { parse_urdf(with_mesh("package://bot/meshes/shell.obj"), "r.urdf", {dir.path() + "/pkgs"}); });
  EXPECT_NE(message.find("not found: looked at [" + dir.path() + "/pkgs/bot/meshes/shell.obj]"), std::string::npos)
      << message;
  EXPECT_NE(message.find("robot.package_path [" + dir.path() + "/pkgs]"), std::string::npos) << message;
  message = invalid_argument_of(
      [&] { parse_urdf(with_mesh("package://nobot/meshes/shell.obj"), "r.urdf", {dir.path() + "/pkgs"}); });
  EXPECT_NE(message.find("package 'nobot' not found in robot.package_path"), std::string::npos) << message;
}

TEST(UrdfModel, MeshFormatsMuJoCoCannotRead) {
  TempFolder dir;
  dir.write("m/shell.dae", "<COLLADA/>");
  dir.write("m/ascii.stl",
            "solid shell\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\n"
            "endloop\nendfacet\nendsolid shell\n");
  std::string message = invalid_argument_of([&] { parse_urdf(with_mesh("m/shell.dae"), dir.path() + "/r.urdf", {}); });
  EXPECT_NE(
      message.find("link 'shell': collision mesh 'm/shell.dae' is COLLADA (.dae); MuJoCo 2.2.2 reads STL and OBJ"),
      std::string::npos)
      << message;
  message = invalid_argument_of([&] { parse_urdf(with_mesh("m/ascii.stl"), dir.path() + "/r.urdf", {}); });
  EXPECT_NE(message.find("is not a binary STL"), std::string::npos) << message;
  message = invalid_argument_of([&] { parse_urdf(with_mesh("m/missing.obj"), dir.path() + "/r.urdf", {}); });
  EXPECT_NE(message.find("mesh file 'm/missing.obj' not found: no file " + dir.path() + "/m/missing.obj"),
            std::string::npos)
      << message;
}

TEST(UrdfModel, VisualDaeMeshesGiveOneNotice) {
  const std::string visual = "<visual><geometry><mesh filename=\"package://gone/a.dae\"/></geometry></visual>";
  std::string text = tiny_bot_urdf();
  for (const std::string link : {"<link name=\"caster\">", "<link name=\"left_wheel\">"})
    text.replace(text.find(link), link.size(), link + visual);
  const UrdfModel urdf = parse_urdf(text, "r.urdf", {});
  ASSERT_EQ(urdf.notices.size(), 1u);
  EXPECT_NE(urdf.notices.front().find("visual DAE meshes skipped (links caster, left_wheel)"), std::string::npos)
      << urdf.notices.front();
}

struct BadUrdf {
  const char* name;
  std::string text;
  const char* message;
};

class UrdfBadInput : public ::testing::TestWithParam<BadUrdf> {};

TEST_P(UrdfBadInput, SaysWhereAndWhatToDo) {
  const std::string message = invalid_argument_of([&] { parse_urdf(GetParam().text, "bad.urdf", {}); });
  EXPECT_NE(message.find(GetParam().message), std::string::npos) << message;
  EXPECT_EQ(message.rfind("bad.urdf", 0), 0u) << message;
}

const std::string kTwoLinks = "<link name=\"a\"/><link name=\"b\"/>";
INSTANTIATE_TEST_SUITE_P(
    Urdf, UrdfBadInput,
    ::testing::Values(
        BadUrdf{"malformed", "<robot name=\"r\">\n<link name=\"a\">\n</robot>",
                "bad.urdf:2: malformed XML: Error=XML_ERROR_MISMATCHED_ELEMENT"},
        BadUrdf{"not_urdf", "<mujoco/>", "the root element is <mujoco>, expected <robot>"},
        BadUrdf{"unknown_parent",
                "<robot name=\"r\">" + kTwoLinks +
                    "\n<joint name=\"j\" type=\"fixed\"><parent link=\"c\"/><child link=\"b\"/></joint></robot>",
                "bad.urdf:2: joint 'j': its parent link 'c' is not in the file (links, nearest first: a, b)"},
        BadUrdf{
            "loop",
            "<robot name=\"r\"><link name=\"root\"/>" + kTwoLinks +
                "<joint name=\"j0\" type=\"fixed\"><parent link=\"root\"/><child link=\"x\"/></joint>"
                "<link name=\"x\"/>\n<joint name=\"j1\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint>"
                "\n<joint name=\"j2\" type=\"fixed\"><parent link=\"b\"/><child link=\"a\"/></joint></robot>",
            "the joints form a loop (a, b, a, each the parent of the one before): remove one of these joints"},
        BadUrdf{"two_parents",
                "<robot name=\"r\"><link name=\"c\"/>" + kTwoLinks +
                    "<joint name=\"j1\" type=\"fixed\"><parent link=\"a\"/><child link=\"b\"/></joint>"
                    "<joint name=\"j2\" type=\"fixed\"><parent link=\"c\"/><child link=\"b\"/></joint></robot>",
                "link 'b' has two parents (joints 'j1' and 'j2')"},
        BadUrdf{"two_roots", "<robot name=\"r\">" + kTwoLinks + "</robot>", "2 links have no parent (a, b)"},
        BadUrdf{"joint_type",
                "<robot name=\"r\">" + kTwoLinks +
                    "<joint name=\"j\" type=\"hinge\"><parent link=\"a\"/><child link=\"b\"/></joint></robot>",
                "joint 'j': unknown joint type 'hinge' (expected fixed|revolute|continuous|prismatic|floating|planar"},
        BadUrdf{"bad_number",
                "<robot name=\"r\">" + kTwoLinks +
                    "<joint name=\"j\" type=\"fixed\"><origin xyz=\"0 0,1 0\"/><parent link=\"a\"/>"
                    "<child link=\"b\"/></joint></robot>",
                "xyz=\"0 0,1 0\": '0,1' is not a finite number"},
        BadUrdf{"shape",
                "<robot name=\"r\"><link name=\"a\"><collision><geometry><capsule radius=\"1\" length=\"1\"/>"
                "</geometry></collision></link></robot>",
                "link 'a': unknown shape <capsule> (URDF has box, cylinder, sphere and mesh)"},
        BadUrdf{"world_root",
                "<robot name=\"r\"><link name=\"world\"/><link name=\"base\"/><joint name=\"j\" "
                "type=\"fixed\"><parent link=\"world\"/><child link=\"base\"/></joint></robot>",
                "the root link is 'world'"}),
    [](const ::testing::TestParamInfo<BadUrdf>& info) { return std::string(info.param.name); });

}  // namespace
}  // namespace stvl::robot_description
