#include "sensors/depth_renderer.hpp"

#include "sensors/reference/depth_renderer.hpp"
#include "sensors/reference/gl_depth_renderer.hpp"
#include "tests/support/fixture.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <vector>

namespace stvl::sensors {
namespace {

using test::looking_along_x;
using World = test::MjWorld;

constexpr double kMedianErrorM = 1e-3;      // rendered vs mj_ray, over pixels valid in both
constexpr double kMismatchFraction = 0.01;  // pixels valid in one image only, or off by more than kOutlierM
constexpr double kOutlierM = 0.05;          // (silhouettes of tessellated shapes)

const char* kShapes = R"(
<mujoco>
  <worldbody>
    <geom type="box" size="6 4 0.05" pos="3 0 -0.05"/>
    <geom type="box" size="0.1 4 3" pos="6 0 1"/>
    <geom type="box" size="0.3 0.3 0.3" pos="2 0.5 0.8" euler="0 0 25"/>
    <geom type="sphere" size="0.4" pos="3 -0.8 1.3"/>
    <geom type="sphere" size="0.15" pos="1.2 -0.3 0.7"/>
    <geom type="cylinder" size="0.25 0.5" pos="2.5 -0.2 0.5"/>
    <geom type="capsule" size="0.1 0.4" pos="4 1.2 1.5" euler="30 0 0"/>
    <geom name="robot_part" type="box" size="0.1 0.1 0.1" pos="1 0 1" group="2"/>
  </worldbody>
</mujoco>)";

struct Comparison {
  double median_abs_error_m = 0.0;
  double mismatch_fraction = 0.0;
  int both_valid = 0;
};

Comparison compare(const DepthImage& a, const DepthImage& b) {
  std::vector<double> errors;
  int mismatch = 0;
  for (size_t i = 0; i < a.depth_m.size(); ++i) {
    const bool va = a.depth_m[i] > 0.0f, vb = b.depth_m[i] > 0.0f;
    if (va && vb) {
      errors.push_back(std::abs(double(a.depth_m[i]) - b.depth_m[i]));
      mismatch += errors.back() > kOutlierM;
    } else if (va != vb) {
      ++mismatch;
    }
  }
  Comparison c;
  c.both_valid = int(errors.size());
  if (!errors.empty()) {
    std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
    c.median_abs_error_m = errors[errors.size() / 2];
  }
  c.mismatch_fraction = double(mismatch) / double(a.depth_m.size());
  return c;
}

// nullptr with the reason when the backend does not work on this machine.
std::unique_ptr<DepthRenderer> try_renderer(const World& world, const CameraIntrinsics& k, GlBackend backend,
                                            std::string& why,
                                            std::array<bool, 6> groups = {true, true, false, true, true, true}) {
  try {
    return std::make_unique<DepthRenderer>(world.model(), k, backend, groups);
  } catch (const std::runtime_error& e) {
    why = std::string(to_string(backend)) + " unavailable: " + e.what();
    return nullptr;
  }
}

class Renderer : public test::MujocoTestWithParam<GlBackend> {
 protected:
  void expect_matches_ray_cast(const CameraIntrinsics& k, const Eigen::Isometry3d& T_world_camera) {
    World world(kShapes);
    std::string why;
    auto renderer = try_renderer(world, k, GetParam(), why);
    if (!renderer) GTEST_SKIP() << why;
    EXPECT_STREQ(renderer->backend_name(), to_string(GetParam()));
    const DepthImage& rendered = renderer->render(world.model(), world.data(), T_world_camera);
    const DepthImage truth = reference::ray_cast_depth(world.model(), world.data(), k, T_world_camera);
    const Comparison c = compare(rendered, truth);
    std::printf("[ %s ] median |rendered - mj_ray| %.2e m over %d pixels, mismatched %.4f%%\n",
                renderer->backend_name(), c.median_abs_error_m, c.both_valid, 100.0 * c.mismatch_fraction);
    EXPECT_GT(c.both_valid, int(0.5 * k.width * k.height));
    EXPECT_LT(c.median_abs_error_m, kMedianErrorM);
    EXPECT_LT(c.mismatch_fraction, kMismatchFraction);
    // A pixel on the tilted box's face, well inside: exact up to depth-buffer precision.
    const auto uv = project_to_pixel(k, T_world_camera.inverse() * Eigen::Vector3d(1.7, 0.5, 0.8));
    ASSERT_TRUE(uv.has_value());
    const int u = int(std::lround(uv->x())), v = int(std::lround(uv->y()));
    if (u >= 0 && v >= 0 && u < k.width && v < k.height) {
      EXPECT_NEAR(rendered.at(u, v), truth.at(u, v), 1e-3) << "pixel " << u << "," << v;
    }
  }
};

TEST_P(Renderer, MatchesRayCastsAt640x480) {
  expect_matches_ray_cast(CameraIntrinsics::d435_640x480(), looking_along_x({0.0, 0.0, 1.0}));
}

TEST_P(Renderer, MatchesRayCastsAt848x480) {
  expect_matches_ray_cast(CameraIntrinsics::d435_848x480(), looking_along_x({0.0, 0.0, 1.0}));
}

// The real 640x480 stream's off-centre principal point (cx 331.39, cy 242.19): a known point lands on the pixel
// project_to_pixel gives, with the depth the ray cast gives (also checked over the whole image above).
TEST_P(Renderer, RealD435At640x480ProjectsAKnownPoint) {
  World world(
      "<mujoco><worldbody><geom type='box' size='0.05 2 2' pos='2.05 0 1'/>"
      "<geom type='box' size='0.02 0.02 0.02' pos='1.5 -0.3 0.8'/></worldbody></mujoco>");
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  std::string why;
  auto renderer = try_renderer(world, k, GetParam(), why);
  if (!renderer) GTEST_SKIP() << why;
  const Eigen::Isometry3d T = looking_along_x({0.0, 0.0, 1.0});
  const DepthImage& image = renderer->render(world.model(), world.data(), T);
  // The small cube's front face at x = 1.48: optical (0.3, 0.2, 1.48) -> u = 331.39 + 390.43 * 0.3 / 1.48.
  const auto uv = project_to_pixel(k, T.inverse() * Eigen::Vector3d(1.48, -0.3, 0.8));
  ASSERT_TRUE(uv.has_value());
  EXPECT_NEAR(uv->x(), 331.39 + 390.43 * 0.3 / 1.48, 1e-9);
  EXPECT_NEAR(uv->y(), 242.19 + 390.43 * 0.2 / 1.48, 1e-9);
  const int u = int(std::lround(uv->x())), v = int(std::lround(uv->y()));
  EXPECT_NEAR(image.at(u, v), 1.48, 2e-3);
  // The cube's face spans 0.04 m / 1.48 m * 390.43 = 10.6 px and its sides about 2 px more (seen obliquely):
  // 9 px away it is the wall at 2.0 m, on every side.
  for (auto [du, dv] : {std::pair{9, 0}, {-9, 0}, {0, 9}, {0, -9}}) EXPECT_NEAR(image.at(u + du, v + dv), 2.0, 2e-3);
  // The optical axis hits the wall at the principal point.
  EXPECT_NEAR(image.at(331, 242), 2.0, 2e-3);
}

TEST_P(Renderer, PrincipalPointOffset) {
  CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  k.cx = 250.0;
  k.cy = 300.0;
  expect_matches_ray_cast(k, looking_along_x({0.0, 0.1, 0.9}));
}

TEST_P(Renderer, RotatedPose) {
  const Eigen::Matrix3d rotation =
      Eigen::AngleAxisd(30.0 * M_PI / 180.0, Eigen::Vector3d(0.3, 1.0, 0.4).normalized()).toRotationMatrix();
  expect_matches_ray_cast(CameraIntrinsics::d435_640x480(), looking_along_x({-0.5, 0.3, 1.2}, rotation));
}

TEST_P(Renderer, RangeLimitsInvalidate) {
  World world(kShapes);
  CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  std::string why;
  auto renderer = try_renderer(world, k, GetParam(), why);
  if (!renderer) GTEST_SKIP() << why;
  // 0.15 m in front of the back wall (closer than min range 0.28 m): nothing valid, nothing drawn through it.
  EXPECT_EQ(renderer->render(world.model(), world.data(), looking_along_x({5.75, 0.0, 1.0})).valid_count(), 0);
  // Looking at the sky from above the scene: nothing within 10 m.
  Eigen::Isometry3d up = looking_along_x({3.0, 0.0, 5.0});
  up.linear() = up.linear() * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  EXPECT_EQ(renderer->render(world.model(), world.data(), up).valid_count(), 0);
  // The back wall at 5.9 m is beyond a 5 m max range.
  k.max_range_m = 5.0;
  DepthRenderer short_range(world.model(), k, renderer->backend());
  const DepthImage& image = short_range.render(world.model(), world.data(), looking_along_x({0.0, 0.0, 1.0}));
  for (float z : image.depth_m) ASSERT_TRUE(z == 0.0f || (z >= 0.28f && z <= 5.0f)) << z;
  EXPECT_EQ(image.at(k.width / 2, 10), 0.0f);  // wall above the shapes
  EXPECT_GT(image.valid_count(), 1000);
}

TEST_P(Renderer, HiddenGeomGroupsAreNotRendered) {
  World world(kShapes);
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  std::string why;
  auto hidden = try_renderer(world, k, GetParam(), why);
  if (!hidden) GTEST_SKIP() << why;
  DepthRenderer shown(world.model(), k, hidden->backend(), {true, true, true, true, true, true});
  const Eigen::Isometry3d T = looking_along_x({0.0, 0.0, 1.0});
  const int u = int(k.cx), v = int(k.cy);  // straight ahead: the group-2 box face at 0.9 m
  EXPECT_NEAR(shown.render(world.model(), world.data(), T).at(u, v), 0.9f, 1e-3);
  EXPECT_NEAR(hidden->render(world.model(), world.data(), T).at(u, v), 5.9f, 1e-3);
}

// A robot with two geoms in group 2 (hidden); the scenario lets the cameras see one of them by moving it to group
// 3 (sim::World::show_robot_geoms_to_cameras, after the renderer was made): that one is drawn, the other is not.
TEST_P(Renderer, RobotGeomMovedToGroupThreeIsDrawnOthersAreNot) {
  World world(R"(
<mujoco>
  <worldbody>
    <geom type="box" size="0.1 4 3" pos="6 0 1"/>
    <geom name="bumper" type="box" size="0.05 0.3 0.05" pos="1 0 0.5" group="2"/>
    <geom name="mast" type="box" size="0.05 0.05 0.5" pos="1.5 0 1.5" group="2"/>
  </worldbody>
</mujoco>)");
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  std::string why;
  auto renderer = try_renderer(world, k, GetParam(), why);
  if (!renderer) GTEST_SKIP() << why;
  const Eigen::Isometry3d T_bumper = looking_along_x({0.0, 0.0, 0.5}), T_mast = looking_along_x({0.0, 0.0, 1.5});
  const int u = int(k.cx), v = int(k.cy);
  EXPECT_NEAR(renderer->render(world.model(), world.data(), T_bumper).at(u, v), 5.9f, 1e-3);  // both hidden
  world.model()->geom_group[mj_name2id(world.model(), mjOBJ_GEOM, "bumper")] = 3;
  EXPECT_NEAR(renderer->render(world.model(), world.data(), T_bumper).at(u, v), 0.95f, 1e-3);  // the bumper's face
  EXPECT_NEAR(renderer->render(world.model(), world.data(), T_mast).at(u, v), 5.9f, 1e-3);     // the mast still hidden
}

TEST_P(Renderer, TwoRenderersInOneProcess) {
  World world(kShapes);
  std::string why;
  CameraIntrinsics crop = CameraIntrinsics::d435_848x480();  // its 640-wide centre crop (not the real 640 stream)
  crop.width = 640;
  crop.cx = 319.5;
  auto first = try_renderer(world, crop, GetParam(), why);
  if (!first) GTEST_SKIP() << why;
  DepthRenderer second(world.model(), CameraIntrinsics::d435_848x480(), GetParam());
  const Eigen::Isometry3d T = looking_along_x({0.0, 0.0, 1.0});
  const DepthImage a = first->render(world.model(), world.data(), T);
  const DepthImage& b = second.render(world.model(), world.data(), T);
  // Same scene, same focal length: the 640 image is the centre crop of the 848 one.
  int compared = 0;
  for (int v = 0; v < 480; v += 7) {
    for (int u = 0; u < 640; u += 7) {
      if (a.at(u, v) > 0.0f && b.at(u + 104, v) > 0.0f) {
        ++compared;
        EXPECT_NEAR(a.at(u, v), b.at(u + 104, v), 2e-3);
      }
    }
  }
  EXPECT_GT(compared, 4000);
  EXPECT_EQ(first->render(world.model(), world.data(), T).depth_m, a.depth_m);  // context switch back and forth
}

TEST_P(Renderer, BadInputThrows) {
  World world(kShapes);
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  std::string why;
  auto renderer = try_renderer(world, k, GetParam(), why);
  if (!renderer) GTEST_SKIP() << why;
  CameraIntrinsics non_square = k;
  non_square.fx = 447.0;
  EXPECT_THROW(DepthRenderer(world.model(), non_square, GetParam()), std::invalid_argument);
  CameraIntrinsics bad = k;
  bad.min_range_m = -1.0;
  EXPECT_THROW(DepthRenderer(world.model(), bad, GetParam()), std::invalid_argument);
  EXPECT_THROW(DepthRenderer(nullptr, k, GetParam()), std::invalid_argument);
  Eigen::Isometry3d scaled = looking_along_x({0.0, 0.0, 1.0});
  scaled.linear() *= 2.0;
  EXPECT_THROW(renderer->render(world.model(), world.data(), scaled), std::invalid_argument);
  World other("<mujoco><worldbody><geom type='sphere' size='1'/></worldbody></mujoco>");
  EXPECT_THROW(renderer->render(other.model(), other.data(), looking_along_x({0, 0, 1})), std::invalid_argument);
  EXPECT_THROW(renderer->render(world.model(), nullptr, looking_along_x({0, 0, 1})), std::invalid_argument);
}

// Pixels whose float bits differ (0 when a and b are the same image).
std::size_t differing_pixels(const DepthImage& a, const DepthImage& b) {
  if (a.depth_m.size() != b.depth_m.size()) return std::max(a.depth_m.size(), b.depth_m.size());
  std::size_t n = 0;
  for (std::size_t i = 0; i < a.depth_m.size(); ++i) n += std::memcmp(&a.depth_m[i], &b.depth_m[i], sizeof(float)) != 0;
  return n;
}

// A view from position_W, yawed about the world's z and pitched down (optical x axis).
Eigen::Isometry3d view(const Eigen::Vector3d& position_W, double yaw_rad, double pitch_rad) {
  Eigen::Isometry3d T =
      looking_along_x(position_W, Eigen::AngleAxisd(-pitch_rad, Eigen::Vector3d::UnitX()).toRotationMatrix());
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() * T.linear();
  return T;
}

// The renderer as it was (colour writes on, mjr_readPixels of float depth) on every pixel: the shipped worlds
// (boxes, cylinders, capsules, spheres, meshes, planes) from several poses, both D435 streams.
TEST_P(Renderer, EveryPixelAsTheFloatReadbackGaveIt) {
  long culled = 0;  // geoms the renderer left out of view (the reference draws every one)
  for (const char* name : {"office_corridor.xml", "cart_crossing.xml", "l_corridor.xml", "mesh_room.xml", "doorway.xml",
                           "ramp_platform.xml"}) {
    char error[1000] = "";
    test::MjModelPtr model(mj_loadXML((test::worlds_dir() + "/" + name).c_str(), nullptr, error, sizeof(error)));
    ASSERT_TRUE(model) << name << ": " << error;
    test::MjDataPtr data(mj_makeData(model.get()));
    mj_forward(model.get(), data.get());
    for (const CameraIntrinsics& k : {CameraIntrinsics::d435_848x480(), CameraIntrinsics::d435_640x480()}) {
      std::unique_ptr<DepthRenderer> fast;
      try {
        fast = std::make_unique<DepthRenderer>(model.get(), k, GetParam());
      } catch (const std::runtime_error& e) {
        GTEST_SKIP() << to_string(GetParam()) << " unavailable: " << e.what();
      }
      reference::FloatDepthRenderer plain(model.get(), k, GetParam());
      long valid = 0;
      for (int pose = 0; pose < 6; ++pose) {
        const Eigen::Isometry3d T =
            view({1.5 * pose, 0.4 * (pose % 3) - 0.4, 0.3 + 0.2 * pose}, 1.1 * pose, 0.1 * pose);
        const DepthImage& before = plain.render(model.get(), data.get(), T);
        const DepthImage& now = fast->render(model.get(), data.get(), T);
        EXPECT_EQ(differing_pixels(now, before), 0u) << name << " " << k.width << "x" << k.height << " pose " << pose;
        valid += before.valid_count();
        culled += fast->culled_geoms();
      }
      EXPECT_GT(valid, 6L * k.width * k.height / 4) << name;  // the poses see something
    }
  }
  EXPECT_GT(culled, 0);  // the comparison covered views with geoms left out
}

// Geoms crossing every side of the image and the far plane as the camera turns and backs away in small steps:
// each image as the reference (which draws every geom) gives it, with geoms left out at most poses.
TEST_P(Renderer, GeomsLeftOutOfViewChangeNoPixel) {
  World world(kShapes);
  std::string why;
  CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  k.max_range_m = 3.0;  // far plane at 7 m: the back wall crosses it as the camera backs away
  auto fast = try_renderer(world, k, GetParam(), why);
  if (!fast) GTEST_SKIP() << why;
  reference::FloatDepthRenderer plain(world.model(), k, GetParam());
  int poses_with_culling = 0, poses = 0;
  for (int step = 0; step < 48; ++step, ++poses) {
    const double yaw = -1.6 + 0.07 * step, pitch = 0.35 * std::sin(0.5 * step);
    const Eigen::Isometry3d T = view({-1.0 - 0.05 * step, 0.3 * std::cos(0.3 * step), 0.9}, yaw, pitch);
    const DepthImage& before = plain.render(world.model(), world.data(), T);
    const DepthImage& now = fast->render(world.model(), world.data(), T);
    EXPECT_EQ(differing_pixels(now, before), 0u) << "step " << step;
    poses_with_culling += fast->culled_geoms() > 0;
  }
  EXPECT_GT(poses_with_culling, poses / 2);
}

TEST_P(Renderer, ConcurrentDrawsGiveTheImagesOfOneAfterAnother) {
  World world(kShapes);
  std::string why;
  auto first = try_renderer(world, CameraIntrinsics::d435_848x480(), GetParam(), why);
  if (!first) GTEST_SKIP() << why;
  DepthRenderer second(world.model(), CameraIntrinsics::d435_640x480(), GetParam());
  DepthRenderer third(world.model(), CameraIntrinsics::d435_848x480(), GetParam());
  const std::vector<DepthRenderer*> all{first.get(), &second, &third};
  for (int round = 0; round < 3; ++round) {
    const std::vector<Eigen::Isometry3d> poses{view({0.1 * round, 0.0, 1.0}, 0.0, 0.1),
                                               view({0.5, 0.2, 0.8}, 0.4 - 0.1 * round, 0.0),
                                               view({1.0, -0.5, 1.2}, -0.3, 0.2)};
    std::vector<DepthImage> alone;
    for (std::size_t i = 0; i < all.size(); ++i) alone.push_back(all[i]->render(world.model(), world.data(), poses[i]));
    render_concurrently(all, world.model(), world.data(), poses);  // takes the contexts this thread holds
    for (std::size_t i = 0; i < all.size(); ++i) {
      EXPECT_EQ(differing_pixels(all[i]->image(), alone[i]), 0u) << "round " << round << ", renderer " << i;
      EXPECT_GT(alone[i].valid_count(), 1000);
    }
  }
  EXPECT_THROW(render_concurrently({first.get(), first.get()}, world.model(), world.data(),
                                   {view({0, 0, 1}, 0, 0), view({0, 0, 1}, 0, 0)}),
               std::invalid_argument);
  EXPECT_THROW(render_concurrently({first.get()}, world.model(), world.data(), {}), std::invalid_argument);
  EXPECT_THROW(second.draw(), std::logic_error);  // nothing prepared
}

INSTANTIATE_TEST_SUITE_P(Backends, Renderer, ::testing::Values(GlBackend::kOsmesa, GlBackend::kEgl),
                         [](const auto& info) { return std::string(to_string(info.param)); });

TEST(RendererBackends, EglAndOsmesaGiveTheSameImage) {
  World world(kShapes);
  const CameraIntrinsics k = CameraIntrinsics::d435_640x480();
  std::string why;
  auto osmesa = try_renderer(world, k, GlBackend::kOsmesa, why);
  if (!osmesa) GTEST_SKIP() << why;
  auto egl = try_renderer(world, k, GlBackend::kEgl, why);
  if (!egl) GTEST_SKIP() << why;
  const Eigen::Isometry3d T = looking_along_x({0.2, -0.1, 1.1});
  const DepthImage a = osmesa->render(world.model(), world.data(), T);
  const DepthImage b = egl->render(world.model(), world.data(), T);
  const Comparison c = compare(a, b);
  std::printf("osmesa vs egl: median %.2e m, mismatched %.4f%%\n", c.median_abs_error_m, 100.0 * c.mismatch_fraction);
  EXPECT_LT(c.median_abs_error_m, 1e-6);
  EXPECT_LT(c.mismatch_fraction, 1e-3);
  EXPECT_EQ(osmesa->render(world.model(), world.data(), T).depth_m, a.depth_m);  // interleaved contexts still work
}

TEST(RendererBackends, AutoHonoursEnvironmentOverride) {
  World world(kShapes);
  ::setenv("STVL_GL", "osmesa", 1);
  std::string why;
  auto renderer = try_renderer(world, CameraIntrinsics::d435_640x480(), GlBackend::kAuto, why);
  if (renderer) {
    EXPECT_STREQ(renderer->backend_name(), "osmesa");
  }
  ::setenv("STVL_GL", "vulkan", 1);
  EXPECT_THROW(DepthRenderer(world.model(), CameraIntrinsics::d435_640x480(), GlBackend::kAuto), std::invalid_argument);
  ::unsetenv("STVL_GL");
  if (!renderer) GTEST_SKIP() << why;
}

// Every 24-bit depth value (with stencil bits set): Mesa's float, then the old conversion, bit for bit, for the
// renderer's planes and odd ones; chunks of an odd length run the vectorized loop's tail.
TEST(DepthFromZ24, EveryDepthValueAsMesasFloatThenTheOldConversion) {
  struct Planes {
    float near_m, far_m, min_m, max_m;
  };
  const CameraIntrinsics k = CameraIntrinsics::d435_848x480();
  const Planes cases[] = {{0.05f, float(2.0 * k.max_range_m + 1.0), float(k.min_range_m), float(k.max_range_m)},
                          {0.01f, 3.0f, 0.02f, 1.0f},
                          {0.05f, 21.0f, 0.0f, 1e30f},
                          {0.2f, 5.0f, 4.9f, 5.0f}};
  std::vector<std::uint32_t> words(std::size_t(1) << 24);
  for (std::uint32_t z = 0; z < words.size(); ++z) words[z] = z << 8 | ((z * 37u) & 0xffu);
  std::vector<float> fast(words.size());
  for (const Planes& p : cases) {
    for (std::size_t at = 0; at < words.size(); at += 4099) {
      const int count = int(std::min<std::size_t>(4099, words.size() - at));
      depth_m_from_z24s8(words.data() + at, fast.data() + at, count, p.near_m, p.far_m, p.min_m, p.max_m);
    }
    std::size_t mismatched = 0, valid = 0;
    for (std::size_t i = 0; i < words.size(); ++i) {
      const float before =
          reference::depth_m_from_gl_depth(reference::mesa_float_depth(words[i]), p.near_m, p.far_m, p.min_m, p.max_m);
      mismatched += std::memcmp(&before, &fast[i], sizeof(float)) != 0;
      valid += before > 0.0f;
    }
    EXPECT_EQ(mismatched, 0u) << "near " << p.near_m << " far " << p.far_m;
    EXPECT_GT(valid, 1000u);
    EXPECT_EQ(fast.back(), 0.0f);  // d = 1: nothing hit
  }
}

}  // namespace
}  // namespace stvl::sensors
