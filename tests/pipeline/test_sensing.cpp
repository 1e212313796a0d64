// Sensing alone, on depth images made here (no simulator): the cloud, the decimation and the band of a frame,
// what the replay of recordings runs too.
#include "pipeline/sensing.hpp"

#include <gtest/gtest.h>

#include "tests/support/wall_frames.hpp"

namespace stvl::pipeline {
namespace {

using test::small_config;
using test::wall_frame;

TEST(Sensing, AWallSeenInARecordedImageBecomesItsObservation) {
  const PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
  Sensing sensing(config);
  Frame f = wall_frame(config, 2.0, 0.5);
  f.T_world_base = Eigen::Translation3d(1.0, 0.0, 0.0) * Eigen::Isometry3d::Identity();
  sensing.sense(f);
  EXPECT_EQ(f.point_count, 64 * 48);
  ASSERT_TRUE(f.observation);
  EXPECT_EQ(f.observation->marking_W.cols(), 64 * 48);  // no filter, no passthrough
  EXPECT_EQ(f.observation->decimated_W, f.observation->marking_W);
  EXPECT_EQ(f.observation->no_return_W.cols(), 0);  // no clear_on_no_return source
  EXPECT_EQ(f.observation->time_s, 0.5);
  EXPECT_TRUE(f.observation->T_world_base.isApprox(f.T_world_base));
  EXPECT_TRUE(f.edge_filtered_depth.depth_m.empty());
  for (Eigen::Index i = 0; i < f.observation->marking_W.cols(); ++i)
    ASSERT_NEAR(f.observation->marking_W(0, i), 2.0f, 1e-5f) << i;
  // Each frame a new observation: the layer's buffers keep the old one.
  const auto first = f.observation;
  sensing.sense(f);
  EXPECT_NE(first, f.observation);
}

// A clear_on_no_return source: the pixels without a return give one point per voxel at its max_z, none with returns.
TEST(Sensing, PixelsWithoutAReturnGiveNoReturnPoints) {
  PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
  config.cameras.front().sources.front().params.clear_on_no_return = true;
  Sensing sensing(config);
  Frame empty = wall_frame(config, 0.0, 0.0);
  sensing.sense(empty);
  ASSERT_GT(empty.observation->no_return_W.cols(), 0);
  for (Eigen::Index i = 0; i < empty.observation->no_return_W.cols(); ++i) {
    const Eigen::Vector3d p = empty.observation->no_return_W.col(i).cast<double>();
    EXPECT_NEAR((p - test::camera_along_x().translation()).norm(), 5.0, 1e-4) << i;
  }
  Frame wall = wall_frame(config, 2.0, 0.0);
  sensing.sense(wall);
  EXPECT_EQ(wall.observation->no_return_W.cols(), 0);
}

// STVL's buffer with `filter: voxel` (PCL's VoxelGrid with the band as z limits): the band first, then the leaves.
// The bench's order decimates the whole cloud and bands the centroids. A wall at 2 m from z 0.23 to 1.77 m, leaves
// of 0.4 m, band [0.9, 1.3]: the leaf row z [1.2, 1.6) has its centroid at about 1.4 m (out of band) in the bench's
// order, while its in-band points alone (z 1.2..1.3) give a centroid inside the band in STVL's.
TEST(Sensing, StvlVoxelFilterBandsBeforeTheLeaves) {
  std::size_t marking[2] = {0, 0};
  for (const bool band_first : {false, true}) {
    PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
    config.filter.type = filter::FilterType::kVoxel;
    config.filter.voxel.voxel_size_m = 0.4;
    config.filter.passthrough_enabled = true;
    config.filter.passthrough = {0.9, 1.3};
    config.filter.band_before_decimation = band_first;
    Sensing sensing(config);
    Frame f = wall_frame(config, 2.0, 0.0);
    sensing.sense(f);
    const layer::Observation& o = *f.observation;
    for (Eigen::Index i = 0; i < o.marking_W.cols(); ++i) {
      EXPECT_GE(o.marking_W(2, i), 0.9f);
      EXPECT_LE(o.marking_W(2, i), 1.3f);
    }
    if (band_first) {
      EXPECT_EQ(o.decimated_W, o.marking_W);  // what marks also clears
    } else {
      EXPECT_GT(o.decimated_W.cols(), o.marking_W.cols());  // the whole wall decimated
    }
    marking[band_first] = static_cast<std::size_t>(o.marking_W.cols());
  }
  EXPECT_GT(marking[1], marking[0]);  // the leaf row at 1.2..1.6 m marks only in STVL's order
}

// voxel_relative: PCL's leaves (and its z limits 0..3 m) are laid in base_link. The wall's points (world y within
// +-1.076, z 0.198..1.802 m) fill 6 x 5 leaves of 0.4 m in the world; with base_link 0.25 m up, z - 0.25 is
// -0.052..1.552 and the points at or above 0 fill 6 x 4.
TEST(Sensing, RelativeVoxelFilterLaysItsLeavesInBaseLink) {
  Eigen::Index centroids[2] = {0, 0};
  for (const auto frame : {mapping::ZReference::kGlobal, mapping::ZReference::kBaseLink}) {
    PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
    config.filter.type = filter::FilterType::kVoxel;
    config.filter.voxel.voxel_size_m = 0.4;
    config.filter.passthrough_enabled = true;
    config.filter.passthrough = {0.0, 3.0};
    config.filter.band_before_decimation = true;
    config.cameras.front().sources.front().params.z_reference = frame;
    Sensing sensing(config);
    Frame f = wall_frame(config, 2.0, 0.0);
    f.T_world_base = Eigen::Translation3d(0.0, 0.0, 0.25) * Eigen::Isometry3d::Identity();
    sensing.sense(f);
    centroids[frame == mapping::ZReference::kBaseLink] = f.observation->decimated_W.cols();
  }
  EXPECT_EQ(centroids[0], 6 * 5);
  EXPECT_EQ(centroids[1], 6 * 4);
}

// Banded marking sources must share one z_reference_frame: the bench filters each cloud once.
TEST(Sensing, MarkingSourcesWithDifferentBandFramesAreRefused) {
  PipelineConfig config = small_config(mapping::ClearingMode::kFrustum);
  auto& sources = config.cameras.front().sources;
  sources.push_back(sources.front());
  sources.back().name = "second";
  sources.back().params.z_reference = mapping::ZReference::kBaseLink;
  EXPECT_THROW(validate_cameras(config), std::invalid_argument);
  sources.back().params.height_band = false;  // filter none: no band, no frame
  EXPECT_NO_THROW(validate_cameras(config));
  EXPECT_EQ(band_frame(config), mapping::ZReference::kGlobal);
}

}  // namespace
}  // namespace stvl::pipeline
