#!/usr/bin/env bash
# In-process A/B of the CPU voxel grid: links filter/voxel_grid.cpp as it is at git revision REV (default HEAD)
# and as it is in the working tree into one program, calls them alternately on the same cloud and prints the
# median times and their ratio (the rest of filter/ is the working tree's for both, so REV's voxel_grid.cpp
# must still compile against today's headers). It first checks that both give bit-identical output (exit 1
# otherwise).
# Alternating calls in one process keeps this machine's drift out of the ratio, which separate runs do not; the
# order within each pair alternates too (with a fixed order the second call was 5-10 % slower, HEAD against
# itself). Run it against HEAD with no change first: the ratio it prints then is the noise floor.
#
#   scripts/ab-voxel-grid.sh [REV] [CLOUD.stvlcld] [VOXEL_M] [THREADS] [REPS]
#   e.g. scripts/ab-voxel-grid.sh HEAD~1 .deps/clouds/corridor_t20.0.stvlcld 0.02 2 200
# Clouds: `build/bin/stvl-bench filter-bench --save-clouds .deps/clouds`. Needs g++ and Eigen only.
set -euo pipefail
cd "$(dirname "$0")/.."
rev=${1:-HEAD}
cloud=${2:-.deps/clouds/corridor_t20.0.stvlcld}
voxel=${3:-0.02}
threads=${4:-2}
reps=${5:-200}
eigen=$( [ -d .deps/eigen3 ] && echo .deps/eigen3 || echo /usr/include/eigen3 )
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
git show "$rev:filter/voxel_grid.cpp" >"$work/old.cpp"
cat >"$work/main.cpp" <<'EOF'
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "filter/cloud_io.hpp"
#include "filter/voxel_grid.hpp"

namespace stvl::filter {
Eigen::Matrix3Xf voxel_grid_old(const Eigen::Matrix3Xf&, const VoxelGridConfig&, int);
}
using namespace stvl::filter;

int main(int, char** argv) {
  const Eigen::Matrix3Xf cloud = load_cloud(argv[1]);
  const VoxelGridConfig config{std::atof(argv[2]), 1};
  const int threads = std::atoi(argv[3]), reps = std::atoi(argv[4]);
  const Eigen::Matrix3Xf a = voxel_grid_old(cloud, config, threads), b = voxel_grid(cloud, config, threads);
  if (a.cols() != b.cols() || !(a.array() == b.array()).all()) {
    std::printf("outputs differ: %ld vs %ld points\n", long(a.cols()), long(b.cols()));
    return 1;
  }
  std::vector<double> ms[2];
  for (int r = 0; r < reps; ++r) {
    for (int k = 0; k < 2; ++k) {
      const int which = (r + k) % 2;  // each goes first in every other pair: the second call of a pair runs slower
      const auto start = std::chrono::steady_clock::now();
      const Eigen::Matrix3Xf out = which ? voxel_grid(cloud, config, threads) : voxel_grid_old(cloud, config, threads);
      ms[which].push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    }
  }
  for (auto& v : ms) std::sort(v.begin(), v.end());
  const double old_ms = ms[0][ms[0].size() / 2], new_ms = ms[1][ms[1].size() / 2];
  std::printf("voxel %.3f m, %d threads, %d calls each, %ld points out: old median %.3f ms, new median %.3f ms, "
              "new/old %.3f\n", config.voxel_size_m, threads, reps, long(b.cols()), old_ms, new_ms, new_ms / old_ms);
}
EOF
flags=(-O3 -DNDEBUG -std=c++17 -I. -I"$work" -isystem "$eigen" -pthread)
g++ "${flags[@]}" -Dvoxel_grid=voxel_grid_old -c "$work/old.cpp" -o "$work/old.o"
g++ "${flags[@]}" "$work/main.cpp" "$work/old.o" filter/voxel_grid.cpp filter/common.cpp filter/cloud_io.cpp \
  -o "$work/ab"
"$work/ab" "$cloud" "$voxel" "$threads" "$reps"
