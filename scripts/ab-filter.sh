#!/usr/bin/env bash
# In-process A/B of a CPU filter (voxel: filter/voxel_grid.cpp, csnb: filter/csnb.cpp): links the filter's
# source as it is at git revision REV (default HEAD) and as it is in the working tree into one program, calls
# them alternately on the same cloud and prints the median times and their ratio (the rest of filter/ is the
# working tree's for both, so REV's file must still compile against today's headers). It first checks that
# both give bit-identical output (exit 1 otherwise).
# Alternating calls in one process keeps this machine's drift out of the ratio, which separate runs do not; the
# order within each pair alternates too (with a fixed order the second call was 5-10 % slower, HEAD against
# itself). Run it against HEAD with no change first: the ratio it prints then is the noise floor.
#
#   scripts/ab-filter.sh voxel|csnb [REV] [CLOUD.stvlcld] [VOXEL_M] [THREADS] [REPS]
#   e.g. scripts/ab-filter.sh voxel HEAD~1 .deps/clouds/corridor_t20.0.stvlcld 0.02 2 200
# Clouds: `build/bin/stvl-bench filter-bench --save-clouds .deps/clouds`. Needs g++ and Eigen only.
set -euo pipefail
cd "$(dirname "$0")/.."
filter=${1:?usage: scripts/ab-filter.sh voxel|csnb [REV] [CLOUD] [VOXEL_M] [THREADS] [REPS]}
case "$filter" in
  voxel) source=filter/voxel_grid.cpp fn=voxel_grid config_type=VoxelGridConfig header=filter/voxel_grid.hpp
         default_reps=200 ;;
  csnb) source=filter/csnb.cpp fn=csnb config_type=CsnbConfig header=filter/csnb.hpp default_reps=30 ;;
  *) echo "ab-filter.sh: unknown filter '$filter' (voxel or csnb)" >&2; exit 2 ;;
esac
rev=${2:-HEAD}
cloud=${3:-.deps/clouds/corridor_t20.0.stvlcld}
voxel=${4:-0.02}
threads=${5:-2}
reps=${6:-$default_reps}
eigen=$( [ -d .deps/eigen3 ] && echo .deps/eigen3 || echo /usr/include/eigen3 )
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
git show "$rev:$source" >"$work/old.cpp"
cat >"$work/main.cpp" <<'EOF'
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "bench/cloud_io.hpp"
#include HEADER

namespace stvl::filter {
Eigen::Matrix3Xf FN_OLD(const Eigen::Matrix3Xf&, const CONFIG&, int);
}
using namespace stvl::filter;

int main(int, char** argv) {
  const Eigen::Matrix3Xf cloud = stvl::bench::load_cloud(argv[1]);
  CONFIG config;
  config.voxel_size_m = std::atof(argv[2]);
  const int threads = std::atoi(argv[3]), reps = std::atoi(argv[4]);
  const Eigen::Matrix3Xf a = FN_OLD(cloud, config, threads), b = FN(cloud, config, threads);
  if (a.cols() != b.cols() || !(a.array() == b.array()).all()) {
    std::printf("outputs differ: %ld vs %ld points\n", long(a.cols()), long(b.cols()));
    return 1;
  }
  std::vector<double> ms[2];
  for (int r = 0; r < reps; ++r) {
    for (int k = 0; k < 2; ++k) {
      const int which = (r + k) % 2;  // each goes first in every other pair: the second call of a pair runs slower
      const auto start = std::chrono::steady_clock::now();
      const Eigen::Matrix3Xf out = which ? FN(cloud, config, threads) : FN_OLD(cloud, config, threads);
      ms[which].push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    }
  }
  for (auto& v : ms) std::sort(v.begin(), v.end());
  const double old_ms = ms[0][ms[0].size() / 2], new_ms = ms[1][ms[1].size() / 2];
  std::printf("%s, voxel %.3f m, %d threads, %d calls each, %ld points out: old median %.3f ms, new median %.3f ms, "
              "new/old %.3f\n", FN_NAME, config.voxel_size_m, threads, reps, long(b.cols()), old_ms, new_ms, new_ms / old_ms);
}
EOF
flags=(-O3 -DNDEBUG -std=c++17 -I. -I"$work" -isystem "$eigen" -pthread "-DFN=$fn" "-DFN_OLD=${fn}_old"
       "-DFN_NAME=\"$fn\"" "-DCONFIG=$config_type" "-DHEADER=\"$header\"")
g++ "${flags[@]}" "-D$fn=${fn}_old" -c "$work/old.cpp" -o "$work/old.o"
g++ "${flags[@]}" "$work/main.cpp" "$work/old.o" "$source" filter/common.cpp bench/cloud_io.cpp \
  -o "$work/ab"
"$work/ab" "$cloud" "$voxel" "$threads" "$reps"
