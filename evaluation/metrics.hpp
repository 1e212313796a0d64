#pragma once
// The figures of one comparison between a map and the truth, each a plain function of voxel and cell sets so
// that it can be checked on hand-made inputs. Keys are world-frame voxel (cell) indices at the evaluation's
// voxel size (common/voxel_key.hpp); "within tol" is the Chebyshev distance between indices.
#include <cstddef>
#include <map>
#include <string>
#include <unordered_map>
#include <vector>

#include "common/voxel_key.hpp"
#include "evaluation/cell_grid.hpp"
#include "mapping/costmap.hpp"
#include "mapping/voxel_map.hpp"

namespace stvl::evaluation {

// True when contains(k') holds for some k' within tol of key (key itself tested first: the usual hit).
template <class Contains>
bool any_within(const VoxelKey& key, int tol, Contains&& contains) {
  if (contains(key)) return true;
  for (int dx = -tol; dx <= tol; ++dx)
    for (int dy = -tol; dy <= tol; ++dy)
      for (int dz = -tol; dz <= tol; ++dz)
        if (contains(VoxelKey{key.x + dx, key.y + dy, key.z + dz})) return true;
  return false;
}

// True when set holds a key within tol of key (any_within() over the set).
bool near_voxel(const VoxelSet& set, const VoxelKey& key, int tol);

// 3D: precision = matched mapped / mapped, recall = matched observed truth / observed truth,
// F1 = 2PR / (P + R), IoU = matched truth / (observed truth + unmatched mapped). Empty denominators give 0.
struct VoxelMatches {
  std::size_t mapped = 0, matched_mapped = 0;         // mapped voxels, and those within tol of a truth voxel
  std::size_t observed_truth = 0, matched_truth = 0;  // observed truth voxels, and those within tol of a mapped one
};
struct VoxelScores {
  double precision = 0, recall = 0, f1 = 0, iou = 0;
};
// Precision, recall, F1 and IoU of matches, as defined above.
VoxelScores voxel_scores(const VoxelMatches& matches);

// An obstacle (one body) over the run: observed once at least min_observed_voxels of its voxels were seen
// within the recall window at one evaluation; detected once, at such an evaluation, at least half of them were
// in the map (within tol).
struct ObstacleResult {
  std::string name;
  std::size_t truth_voxels = 0;     // surface voxels in the height band (the most at any time)
  std::size_t observed_voxels = 0;  // the most seen at one evaluation
  double best_recall = 0;           // the best fraction of its observed voxels in the map at one evaluation
  bool observed = false;
  bool detected = false;
};
// One evaluation of the obstacle: observed_voxels of it seen in the window, matched_voxels of those in the map.
void update_obstacle(ObstacleResult& obstacle, std::size_t observed_voxels, std::size_t matched_voxels,
                     int min_observed_voxels);

// 2D: lethal cells against the true footprints. precision = lethal cells within tol of a footprint cell /
// lethal cells; recall = observed footprint cells within tol of a lethal cell / observed footprint cells.
struct CostmapMatches {
  std::size_t lethal = 0, lethal_true = 0;
  std::size_t observed = 0, observed_hit = 0;
  double precision = 0, recall = 0;
  std::vector<CellKey> true_positive, false_positive, false_negative;  // for pictures, row by row
};
// The 2D figures above, and the cells for pictures; footprint: the true footprint cells, observed: those seen.
CostmapMatches match_costmap(const CellGrid& lethal, const CellGrid& footprint, const CellGrid& observed, int tol);
// Cell keys (at cell_m, the costmap's own resolution) of the lethal cells of a costmap.
CellGrid lethal_cells(const mapping::Costmap2D& costmap, double cell_m);

// A guard on the projection (costmap ghosts, STVL #199/#94/#60), recomputed from the voxels themselves: a column
// (cell of the voxel size) should be lethal exactly where it holds >= max(mark_threshold, 1) voxels whose centre
// z lies in [min_z_m, max_z_m].
struct ProjectionGuard {
  std::size_t lethal_without_voxels = 0;   // lethal cells whose column holds too few voxels in the band
  std::size_t columns_without_lethal = 0;  // columns with enough voxels in the band and no lethal cell
};
// freed: cells the costmap set free on purpose (STVL's footprint clearing); their columns are not counted.
ProjectionGuard guard_projection(const mapping::VoxelMap& map, const CellGrid& lethal, double min_z_m, double max_z_m,
                                 const CellSet& freed = {});
// The same from the voxels per column in the band (column_counts(): a count per cell from
// VoxelMap::for_each_column, which the projection also counts with; both tested against a count per voxel, so the
// guard checks what follows the count: threshold, resolution, the cells freed) and max(mark_threshold, 1).
CellGrid column_counts(const mapping::VoxelMap& map, double min_z_m, double max_z_m);
ProjectionGuard guard_projection(const CellGrid& counts, int needed, const CellGrid& lethal, const CellSet& freed);

// The robot marking itself (STVL issue #214): lethal cells inside the footprint's convex fill (the cells STVL's
// footprint clearing frees, mapping::footprint_cells) and in a ring of cells whose centres lie within ring_m
// outside the polygon. A cell with a true footprint cell within tol cells is an obstacle beside the robot,
// not the robot, and is not counted. footprint_W: the robot's polygon in the world; fewer than 3 points: 0, 0.
struct SelfMarking {
  std::size_t inside = 0, ring = 0;
  std::size_t total() const { return inside + ring; }  // inside and ring together
};
// Counts it as above: cell_m the cell size, ring_m the ring's width (metres); truth_footprint: the true cells.
SelfMarking count_self_marking(const CellGrid& lethal, const std::vector<Eigen::Vector2d>& footprint_W, double cell_m,
                               double ring_m, const CellGrid& truth_footprint, int tol);

// A phantom obstacle: an 8-connected group of at least min_cells lethal cells with no true footprint cell
// centre within clearance_m of any of its cell centres (Chebyshev, ceil(clearance_m / cell_m) cells).
struct Phantom {
  double x_m = 0, y_m = 0;  // the mean of its cell centres, world frame
  std::size_t cells = 0;
};
// Sorted by position (x, then y).
std::vector<Phantom> find_phantoms(const CellGrid& lethal, const CellGrid& footprint, double cell_m, double clearance_m,
                                   int min_cells);

// Another costmap's lethal cells (nav2's master costmap, any resolution and origin) against the true footprint
// (cells of cell_m): each lethal cell stands for the cell_m cells its square covers (their centres inside it). A
// lethal cell is false when none of them has a true footprint cell within tol cells; phantoms as find_phantoms()
// over the covered cells.
struct LethalVsTruth {
  std::size_t lethal = 0, false_lethal = 0;
  std::vector<Phantom> phantoms;
};
LethalVsTruth lethal_against_truth(const mapping::Costmap2D& costmap, const CellGrid& footprint, double cell_m, int tol,
                                   double clearance_m, int min_cells);

// Lethal cells where the robot must drive (issue 31): of `free_lethal` (lethal cells with no true footprint cell
// within tolerance: match_costmap's false positives), those whose centre lies within corridor_m of the polyline
// path_W. first_*: the one nearest the path's start along the path (its arc length), for messages.
struct PathBlock {
  std::size_t cells = 0;
  double first_x_m = 0, first_y_m = 0, first_along_m = 0;
};
// Counts them as above; cell_m the cell size. A path of fewer than 2 points blocks nothing.
PathBlock lethal_near_path(const std::vector<CellKey>& free_lethal, const std::vector<Eigen::Vector2d>& path_W,
                           double cell_m, double corridor_m);

// Distance of mapped voxel centres to the nearest true surface.
struct DistanceStats {
  std::size_t count = 0;
  double mean_m = 0, median_m = 0, p90_m = 0, p99_m = 0, max_m = 0;
};
// Quantiles are the nearest rank (index round(q (n - 1)) of the sorted values).
DistanceStats distance_stats(std::vector<double> distances_m);
// The same from each distinct distance and how often it occurred (identical figures, the mean summed in the same
// sorted order): memory bounded by the distinct values, not by the run's length (issue #270, soak).
DistanceStats distance_stats_of_counts(const std::map<double, std::size_t>& counts_m);

}  // namespace stvl::evaluation
