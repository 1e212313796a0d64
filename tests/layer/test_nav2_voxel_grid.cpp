// nav2's voxel grid (layer/nav2_voxel_grid.hpp, after navigation2 main a3a97043 nav2_voxel_grid): a column's bits,
// its marked and unknown counts against the thresholds and the 2D cells they set, and nav2's 3D line walk on lines
// whose voxels are derived by hand below from nav2's bresenham3D. The same walk is compared with an independent
// Python model on random lines by nav2_voxel_grid_check.py (ctest layer.nav2_voxel_grid_python).
#include "layer/nav2_voxel_grid.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace stvl::layer::nav2 {
namespace {

using Voxel = std::array<unsigned, 3>;

// The voxels raytrace_line visits, in order; each z_mask must be a level's two bits.
std::vector<Voxel> walk(const VoxelGrid& grid, double x0, double y0, double z0, double x1, double y1, double z1,
                        unsigned max_length = kNoMaxLength, unsigned min_length = 0, bool* inside = nullptr) {
  std::vector<Voxel> visited;
  const bool ok = grid.raytrace_line(
      [&](std::size_t index, std::uint32_t z_mask) {
        unsigned z = 0;
        while (z < 16 && z_mask != (0x00010001u << z)) ++z;
        EXPECT_LT(z, 16u) << "z_mask " << z_mask;
        EXPECT_LT(index, grid.columns().size());
        visited.push_back({static_cast<unsigned>(index % grid.size_x_cells()),
                           static_cast<unsigned>(index / grid.size_x_cells()), z});
      },
      x0, y0, z0, x1, y1, z1, max_length, min_length);
  if (inside != nullptr) *inside = ok;
  return visited;
}

TEST(Nav2VoxelGrid, MarkingAndClearingSetTheTwoBitsOfALevel) {
  VoxelGrid grid(2, 1, 16);
  // New: every level unknown, the low half set.
  EXPECT_EQ(grid.column(0, 0), 0x0000ffffu);
  EXPECT_EQ(grid.voxel(0, 0, 0), VoxelStatus::kUnknown);
  // Marking level 0 sets its marked bit 16 (its low bit 0 was already set); level 15 sets bit 31.
  grid.mark_voxel(0, 0, 0);
  EXPECT_EQ(grid.column(0, 0), 0x0001ffffu);
  grid.mark_voxel(0, 0, 15);
  EXPECT_EQ(grid.column(0, 0), 0x8001ffffu);
  EXPECT_EQ(grid.voxel(0, 0, 0), VoxelStatus::kMarked);
  EXPECT_EQ(grid.voxel(0, 0, 15), VoxelStatus::kMarked);
  // Clearing level 0 clears both its bits: free, not unknown; level 1 is still unknown.
  grid.clear_voxel(0, 0, 0);
  EXPECT_EQ(grid.column(0, 0), 0x8000fffeu);
  EXPECT_EQ(grid.voxel(0, 0, 0), VoxelStatus::kFree);
  EXPECT_EQ(grid.voxel(0, 0, 1), VoxelStatus::kUnknown);
  // Marking a free level sets both bits again.
  grid.mark_voxel(0, 0, 0);
  EXPECT_EQ(grid.column(0, 0), 0x8001ffffu);
  // The other column is untouched; outside the grid nothing changes and the voxel reads unknown.
  EXPECT_EQ(grid.column(1, 0), 0x0000ffffu);
  grid.mark_voxel(2, 0, 0);
  grid.mark_voxel(0, 1, 0);
  grid.mark_voxel(0, 0, 16);
  grid.clear_voxel(0, 0, 16);
  EXPECT_EQ(grid.column(0, 0), 0x8001ffffu);
  EXPECT_EQ(grid.column(1, 0), 0x0000ffffu);
  EXPECT_EQ(grid.voxel(2, 0, 0), VoxelStatus::kUnknown);
  EXPECT_EQ(grid.voxel(0, 0, 16), VoxelStatus::kUnknown);
  // nav2's clearVoxelColumn: every level free, those above size_z too.
  grid.clear_voxel_column(0);
  EXPECT_EQ(grid.column(0, 0), 0u);
  EXPECT_THROW(grid.clear_voxel_column(2), std::out_of_range);
  // A lone marked bit (no operation makes one) has one bit of its level set: getVoxel calls it unknown.
  grid.columns()[1] = 0x00010000u;
  EXPECT_EQ(grid.voxel(1, 0, 0), VoxelStatus::kUnknown);
}

TEST(Nav2VoxelGrid, LevelsAtAndAboveSizeZAreNeitherMarkedNorClearedButStayUnknown) {
  VoxelGrid grid(1, 1, 4);
  grid.mark_voxel(0, 0, 4);  // level 4 is outside a grid of 4 levels
  grid.clear_voxel(0, 0, 4);
  EXPECT_EQ(grid.column(0, 0), 0x0000ffffu);
  EXPECT_EQ(grid.voxel(0, 0, 4), VoxelStatus::kUnknown);
  // Clearing all four levels leaves levels 4..15 unknown: 12 unknown bits (why VoxelLayer adds 16 - z_voxels to
  // unknown_threshold).
  for (unsigned z = 0; z < 4; ++z) grid.clear_voxel(0, 0, z);
  EXPECT_EQ(grid.column(0, 0), 0x0000fff0u);
  EXPECT_EQ(grid.voxel_column(0, 0, 11, 0), VoxelStatus::kUnknown);  // 12 > 11
  EXPECT_EQ(grid.voxel_column(0, 0, 12, 0), VoxelStatus::kFree);     // 12 <= 12
}

TEST(Nav2VoxelGrid, BitCounts) {
  EXPECT_EQ(num_bits(0u), 0u);
  EXPECT_EQ(num_bits(0x80000001u), 2u);
  EXPECT_EQ(num_bits(0xffffffffu), 32u);
  EXPECT_TRUE(bits_at_most(0x7u, 3));  // 3 bits: at most 3
  EXPECT_FALSE(bits_at_most(0x7u, 2));
  EXPECT_TRUE(bits_at_most(0u, 0));
}

TEST(Nav2VoxelGrid, MarkVoxelInMapSaysWhenTheColumnHoldsMoreThanMarkThreshold) {
  VoxelGrid grid(1, 1, 4);
  EXPECT_TRUE(grid.mark_voxel_in_map(0, 0, 0, 0));   // 1 marked > 0
  EXPECT_FALSE(grid.mark_voxel_in_map(0, 0, 1, 2));  // 2 marked, not > 2
  EXPECT_TRUE(grid.mark_voxel_in_map(0, 0, 2, 2));   // 3 marked > 2
  EXPECT_FALSE(grid.mark_voxel_in_map(0, 0, 4, 0));  // outside: nothing
  EXPECT_EQ(grid.column(0, 0), 0x0007ffffu);
}

TEST(Nav2VoxelGrid, ColumnStatusWeighsMarkedFirstThenUnknown) {
  VoxelGrid grid(1, 1, 16);
  // Level 3 marked, levels 0..2 free: marked bits 0x0008 (1), unknown 0x0008 ^ 0xfff8 = 0xfff0 (12).
  grid.mark_voxel(0, 0, 3);
  for (unsigned z = 0; z < 3; ++z) grid.clear_voxel(0, 0, z);
  EXPECT_EQ(grid.column(0, 0), 0x0008fff8u);
  EXPECT_EQ(grid.voxel_column(0, 0, 12, 0), VoxelStatus::kMarked);   // 1 marked > 0, whatever the unknown
  EXPECT_EQ(grid.voxel_column(0, 0, 11, 1), VoxelStatus::kUnknown);  // not marked (1 <= 1); 12 unknown > 11
  EXPECT_EQ(grid.voxel_column(0, 0, 12, 1), VoxelStatus::kFree);
  EXPECT_EQ(grid.voxel_column(1, 0, 16, 16), VoxelStatus::kUnknown);  // outside
}

TEST(Nav2VoxelGrid, ClearingALineSetsThe2DCellByTheColumnsCounts) {
  // One column of 4 levels; level 3 marked. The line clears levels 0..2, leaving 1 marked and 12 unknown
  // (levels 4..15) as in the test above.
  const auto cleared = [](unsigned unknown_threshold, unsigned mark_threshold, std::uint8_t free_cost = 0,
                          std::uint8_t unknown_cost = 255) {
    VoxelGrid grid(1, 1, 4);
    grid.mark_voxel(0, 0, 3);
    std::vector<std::uint8_t> map_2d{77};
    EXPECT_TRUE(grid.clear_voxel_line_in_map(0.5, 0.5, 0.5, 0.5, 0.5, 2.5, &map_2d, unknown_threshold, mark_threshold,
                                             free_cost, unknown_cost));
    EXPECT_EQ(grid.column(0, 0), 0x0008fff8u);
    return static_cast<int>(map_2d[0]);
  };
  EXPECT_EQ(cleared(16, 0), 77);       // 1 marked > 0: the cell keeps its cost
  EXPECT_EQ(cleared(11, 1), 255);      // marked 1 <= 1, unknown 12 > 11: NO_INFORMATION
  EXPECT_EQ(cleared(12, 1), 0);        // unknown 12 <= 12: FREE_SPACE
  EXPECT_EQ(cleared(12, 1, 7, 9), 7);  // the costs are the caller's
  EXPECT_EQ(cleared(11, 1, 7, 9), 9);
  // Without a 2D map only the voxels; a map of the wrong size is refused.
  VoxelGrid grid(1, 1, 4);
  EXPECT_TRUE(grid.clear_voxel_line_in_map(0.5, 0.5, 0.5, 0.5, 0.5, 2.5, nullptr, 0, 0));
  EXPECT_EQ(grid.column(0, 0), 0x0000fff8u);
  std::vector<std::uint8_t> wrong(2, 0);
  EXPECT_THROW(grid.clear_voxel_line_in_map(0.5, 0.5, 0.5, 0.5, 0.5, 2.5, &wrong, 0, 0), std::invalid_argument);
}

TEST(Nav2VoxelGrid, ClearVoxelInMapFreesTheCellAtMostOneMarkedAndOneUnknown) {
  VoxelGrid grid(3, 1, 16);
  std::vector<std::uint8_t> map_2d{77, 77, 77};
  grid.columns()[0] = 0x00030003u;           // levels 0, 1 marked, the rest free
  grid.columns()[1] = 0x00070007u;           // levels 0..2 marked
  grid.clear_voxel_in_map(0, 0, 0, map_2d);  // 1 marked, 0 unknown: free
  grid.clear_voxel_in_map(1, 0, 0, map_2d);  // 2 marked: kept
  grid.clear_voxel_in_map(2, 0, 0, map_2d);  // all unknown: 15 unknown, kept
  EXPECT_EQ(grid.column(0, 0), 0x00020002u);
  EXPECT_EQ(grid.column(1, 0), 0x00060006u);
  EXPECT_EQ(grid.column(2, 0), 0x0000fffeu);
  EXPECT_EQ(map_2d, (std::vector<std::uint8_t>{0, 77, 77}));
}

// (0,0,0) -> (5,2,1): dx 5, dy 2, dz 1; x dominates (5 >= max(2, 1)), 5 steps, both errors start at 5 / 2 = 2.
// step 0: visit (0,0,0); x 1; ey 2+2 = 4, ez 2+1 = 3
// step 1: visit (1,0,0); x 2; ey 6 >= 5: y 1, ey 1; ez 4
// step 2: visit (2,1,0); x 3; ey 3; ez 5 >= 5: z 1, ez 0
// step 3: visit (3,1,1); x 4; ey 5 >= 5: y 2, ey 0; ez 1
// step 4: visit (4,2,1); x 5; ey 2; ez 2
// then the last voxel (5,2,1).
TEST(Nav2VoxelGrid, TheWalkOfALineVisitsNav2sVoxels) {
  const VoxelGrid grid(6, 3, 2);
  const std::vector<Voxel> line = {{0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {3, 1, 1}, {4, 2, 1}, {5, 2, 1}};
  EXPECT_EQ(walk(grid, 0, 0, 0, 5, 2, 1), line);
  // Clearing it frees exactly those 6 voxels of the 36; marking marks exactly them.
  VoxelGrid cleared(6, 3, 2), marked(6, 3, 2);
  EXPECT_TRUE(cleared.clear_voxel_line(0, 0, 0, 5, 2, 1));
  EXPECT_TRUE(marked.mark_voxel_line(0, 0, 0, 5, 2, 1));
  int free = 0, mark = 0;
  for (unsigned z = 0; z < 2; ++z)
    for (unsigned y = 0; y < 3; ++y)
      for (unsigned x = 0; x < 6; ++x) {
        const bool on_line = std::find(line.begin(), line.end(), Voxel{x, y, z}) != line.end();
        EXPECT_EQ(cleared.voxel(x, y, z), on_line ? VoxelStatus::kFree : VoxelStatus::kUnknown) << x << y << z;
        EXPECT_EQ(marked.voxel(x, y, z), on_line ? VoxelStatus::kMarked : VoxelStatus::kUnknown) << x << y << z;
        free += cleared.voxel(x, y, z) == VoxelStatus::kFree;
        mark += marked.voxel(x, y, z) == VoxelStatus::kMarked;
      }
  EXPECT_EQ(free, 6);
  EXPECT_EQ(mark, 6);
}

TEST(Nav2VoxelGrid, MaxLengthClipsTheStepsOfTheDominantAxis) {
  const VoxelGrid grid(10, 10, 16);
  // max 3 over length sqrt(30) = 5.477: int(3 / 5.477 * 5) = int(2.74) = 2 steps, so 3 voxels.
  EXPECT_EQ(walk(grid, 0, 0, 0, 5, 2, 1, 3), (std::vector<Voxel>{{0, 0, 0}, {1, 0, 0}, {2, 1, 0}}));
  EXPECT_EQ(walk(grid, 0, 0, 0, 5, 2, 1, 0), (std::vector<Voxel>{{0, 0, 0}}));  // no step: the start only
  EXPECT_EQ(walk(grid, 0, 0, 0, 5, 2, 1, 6).size(), 6u);                        // 6 >= 5.477: the whole line
  // min 3 on (0.5,0.5,0.5) -> (9.5,0.5,0.5), length 9: the start moves to x 3.5, dx = 9 - 3 = 6: x 3..9.
  const std::vector<Voxel> from3 = {{3, 0, 0}, {4, 0, 0}, {5, 0, 0}, {6, 0, 0}, {7, 0, 0}, {8, 0, 0}, {9, 0, 0}};
  EXPECT_EQ(walk(grid, 0.5, 0.5, 0.5, 9.5, 0.5, 0.5, kNoMaxLength, 3), from3);
  // With max 5 too, nav2 scales the 6 remaining cells by 5 / 9 (the whole line's length): int(3.33) = 3 steps,
  // x 3..6, one cell past 0.5 + 5 = 5.5.
  EXPECT_EQ(walk(grid, 0.5, 0.5, 0.5, 9.5, 0.5, 0.5, 5, 3), (std::vector<Voxel>(from3.begin(), from3.begin() + 4)));
  // Shorter than min_length (int(9) < 10): nothing, though the line is inside.
  bool inside = false;
  EXPECT_TRUE(walk(grid, 0.5, 0.5, 0.5, 9.5, 0.5, 0.5, kNoMaxLength, 10, &inside).empty());
  EXPECT_TRUE(inside);
  // A point: its voxel once (nav2's bresenham3DSamePoint).
  EXPECT_EQ(walk(grid, 2.2, 3.8, 0.4, 2.2, 3.8, 0.4), (std::vector<Voxel>{{2, 3, 0}}));
}

TEST(Nav2VoxelGrid, LinesAlongEachAxisAndDiagonals) {
  const VoxelGrid grid(6, 6, 16);
  EXPECT_EQ(walk(grid, 0.5, 2.5, 3.5, 4.5, 2.5, 3.5),
            (std::vector<Voxel>{{0, 2, 3}, {1, 2, 3}, {2, 2, 3}, {3, 2, 3}, {4, 2, 3}}));
  EXPECT_EQ(walk(grid, 4.9, 0, 0, 0.1, 0, 0),
            (std::vector<Voxel>{{4, 0, 0}, {3, 0, 0}, {2, 0, 0}, {1, 0, 0}, {0, 0, 0}}));
  EXPECT_EQ(walk(grid, 1.5, 0.2, 0.7, 1.5, 3.9, 0.7), (std::vector<Voxel>{{1, 0, 0}, {1, 1, 0}, {1, 2, 0}, {1, 3, 0}}));
  // Ties go to x: errors start at 1, gain 3 a step and reach 3 each time, so every axis steps every time.
  EXPECT_EQ(walk(grid, 0, 0, 0, 3, 3, 3), (std::vector<Voxel>{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {3, 3, 3}}));
  EXPECT_EQ(walk(grid, 0.5, 3.5, 0.5, 3.5, 0.5, 0.5), (std::vector<Voxel>{{0, 3, 0}, {1, 2, 0}, {2, 1, 0}, {3, 0, 0}}));
  // y dominant (0,0,0) -> (2,5,1), errors from 2: x steps after visits 1 and 3 (ex 6, 5), z after visit 2 (ez 5).
  EXPECT_EQ(walk(grid, 0, 0, 0, 2, 5, 1),
            (std::vector<Voxel>{{0, 0, 0}, {0, 1, 0}, {1, 2, 0}, {1, 3, 1}, {2, 4, 1}, {2, 5, 1}}));
  // z dominant (0,0,0) -> (1,2,5), errors from 2: y steps after visits 1 and 3 (ey 6, 5), x after visit 2 (ex 5).
  EXPECT_EQ(walk(grid, 0, 0, 0, 1, 2, 5),
            (std::vector<Voxel>{{0, 0, 0}, {0, 0, 1}, {0, 1, 2}, {1, 1, 3}, {1, 2, 4}, {1, 2, 5}}));
}

TEST(Nav2VoxelGrid, AVerticalLineReachesLevels0And15) {
  VoxelGrid grid(2, 2, 16);
  std::vector<Voxel> down;
  for (unsigned z = 16; z-- > 0;) down.push_back({1, 1, z});
  EXPECT_EQ(walk(grid, 1.5, 1.5, 15.5, 1.5, 1.5, 0.5), down);
  // Marking then clearing the whole column through the lines: all 32 bits set, then none.
  EXPECT_TRUE(grid.mark_voxel_line(1.5, 1.5, 0.5, 1.5, 1.5, 15.9));
  EXPECT_EQ(grid.column(1, 1), 0xffffffffu);
  EXPECT_TRUE(grid.clear_voxel_line(1.5, 1.5, 15.9, 1.5, 1.5, 0.0));
  EXPECT_EQ(grid.column(1, 1), 0u);
  EXPECT_EQ(grid.column(0, 1), 0x0000ffffu);
}

TEST(Nav2VoxelGrid, ALineWithAnEndpointOutsideTheGridDoesNothing) {
  // nav2's *Line functions refuse an endpoint coordinate >= the size; below 0 nav2 does not check: in (-1, 0) the
  // truncations give 0, at -1 or below nav2 would index outside its array, which this grid refuses too.
  VoxelGrid grid(4, 4, 4);
  std::vector<std::uint8_t> map_2d(16, 77);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(grid.clear_voxel_line(1.5, 1.5, 1.5, 4.0, 1.5, 1.5));  // x1 == size_x
  EXPECT_FALSE(grid.mark_voxel_line(1.5, 1.5, 1.5, 1.5, 1.5, 4.0));   // z1 == size_z
  EXPECT_FALSE(grid.clear_voxel_line_in_map(1.5, 1.5, 1.5, 1.5, 9.0, 1.5, &map_2d, 16, 16));
  EXPECT_FALSE(grid.clear_voxel_line(1.5, 1.5, 1.5, 1.5, 1.5, -1.0));
  EXPECT_FALSE(grid.clear_voxel_line(nan, 1.5, 1.5, 1.5, 1.5, 1.0));
  for (const std::uint32_t c : grid.columns()) EXPECT_EQ(c, 0x0000ffffu);
  EXPECT_EQ(map_2d, std::vector<std::uint8_t>(16, 77));
  // Just inside: -0.5 walks as 0, 3.999 as 3.
  EXPECT_EQ(walk(grid, -0.5, 0.5, 0.5, 3.999, 0.5, 0.5),
            (std::vector<Voxel>{{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}}));
}

TEST(Nav2VoxelGrid, ResizeTakesUpTo16LevelsAndRejectsMoreNamingZVoxels) {
  VoxelGrid grid(2, 3, 16);
  EXPECT_EQ(grid.size_z_cells(), 16u);
  grid.mark_voxel(1, 2, 15);
  EXPECT_THROW(VoxelGrid(2, 3, 17), std::invalid_argument);
  try {
    grid.resize(2, 3, 17);
    FAIL() << "resize to 17 levels";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("z_voxels"), std::string::npos) << e.what();
  }
  // The refused resize left the grid as it was.
  EXPECT_EQ(grid.size_z_cells(), 16u);
  EXPECT_EQ(grid.voxel(1, 2, 15), VoxelStatus::kMarked);
  // A resize (the same sizes too) and a reset make every voxel unknown.
  grid.resize(2, 3, 16);
  EXPECT_EQ(grid.voxel(1, 2, 15), VoxelStatus::kUnknown);
  grid.mark_voxel(0, 0, 0);
  grid.reset();
  EXPECT_EQ(grid.column(0, 0), 0x0000ffffu);
  grid.resize(3, 2, 8);
  EXPECT_EQ(grid.size_x_cells(), 3u);
  EXPECT_EQ(grid.size_y_cells(), 2u);
  EXPECT_EQ(grid.size_z_cells(), 8u);
  EXPECT_EQ(grid.columns(), std::vector<std::uint32_t>(6, 0x0000ffffu));
}

}  // namespace
}  // namespace stvl::layer::nav2
