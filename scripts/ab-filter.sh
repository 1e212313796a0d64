#!/usr/bin/env bash
# In-process A/B of a CPU filter (voxel grid or CSNB): compiles filter/ as it is at git revision REV (default
# HEAD) and as it is in the working tree into one program (REV's copy in namespace stvl_old, so the two never
# share a symbol, whatever files either splits its code into), calls them alternately on the same cloud and
# prints the median times and their ratio. It first checks that both give bit-identical output (exit 1
# otherwise). Both sides use TBB when its headers are installed (-DSTVL_FILTER_TBB=1), as the build does.
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
  voxel) fn=voxel_grid config_type=VoxelGridConfig header=filter/voxel_grid.hpp default_reps=100 ;;
  csnb) fn=csnb config_type=CsnbConfig header=filter/csnb.hpp default_reps=30 ;;
  *) echo "ab-filter.sh: unknown filter '$filter' (voxel or csnb)" >&2; exit 2 ;;
esac
rev=${2:-HEAD}
cloud=${3:-.deps/clouds/corridor_t20.0.stvlcld}
voxel=${4:-0.02}
threads=${5:-2}
reps=${6:-$default_reps}
[[ -f "$cloud" ]] || { echo "ab-filter.sh: no cloud file $cloud (see the header of this script)" >&2; exit 2; }
eigen=$( [ -d .deps/eigen3 ] && echo .deps/eigen3 || echo /usr/include/eigen3 )
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/old"
# Revisions before common/ existed have filter/ alone.
git archive "$rev" filter common 2>/dev/null | tar -x -C "$work/old" 2>/dev/null || git archive "$rev" filter | tar -x -C "$work/old"
tbb=()
if [[ -f /usr/include/tbb/parallel_for.h || -f /usr/include/oneapi/tbb/parallel_for.h ]]; then tbb=(-DSTVL_FILTER_TBB=1); fi

# One entry point per side: ab_old / ab_new(cloud, voxel, threads).
for side in old new; do
  printf '#include "%s"\nEigen::Matrix3Xf ab_%s(const Eigen::Matrix3Xf& cloud, double voxel_m, int threads) {\n  stvl::filter::%s config;\n  config.voxel_size_m = voxel_m;\n  return stvl::filter::%s(cloud, config, threads);\n}\n' \
    "$header" "$side" "$config_type" "$fn" >"$work/entry_$side.cpp"
done
cat >"$work/main.cpp" <<'EOF'
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "bench/cloud_io.hpp"

Eigen::Matrix3Xf ab_old(const Eigen::Matrix3Xf&, double, int);
Eigen::Matrix3Xf ab_new(const Eigen::Matrix3Xf&, double, int);

int main(int, char** argv) {
  const Eigen::Matrix3Xf cloud = stvl::bench::load_cloud(argv[1]);
  const double voxel_m = std::atof(argv[2]);
  const int threads = std::atoi(argv[3]), reps = std::atoi(argv[4]);
  const Eigen::Matrix3Xf a = ab_old(cloud, voxel_m, threads), b = ab_new(cloud, voxel_m, threads);
  if (a.cols() != b.cols() || !(a.array() == b.array()).all()) {
    std::printf("outputs differ: %ld vs %ld points\n", long(a.cols()), long(b.cols()));
    return 1;
  }
  std::vector<double> ms[2];
  for (int r = 0; r < reps; ++r) {
    for (int k = 0; k < 2; ++k) {
      const int which = (r + k) % 2;  // each goes first in every other pair: the second call of a pair runs slower
      const auto start = std::chrono::steady_clock::now();
      const Eigen::Matrix3Xf out = which ? ab_new(cloud, voxel_m, threads) : ab_old(cloud, voxel_m, threads);
      ms[which].push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
    }
  }
  for (auto& v : ms) std::sort(v.begin(), v.end());
  const double old_ms = ms[0][ms[0].size() / 2], new_ms = ms[1][ms[1].size() / 2];
  std::printf("%s, voxel %.3f m, %d threads, %d calls each, %ld points out: old median %.3f ms, new median %.3f ms, "
              "new/old %.3f\n", FN_NAME, voxel_m, threads, reps, long(b.cols()), old_ms, new_ms, new_ms / old_ms);
}
EOF
flags=(-O3 -DNDEBUG -std=c++17 -isystem "$eigen" -pthread "${tbb[@]}")
# The algorithm sources only (filter.cpp holds the CUDA dispatch, which neither side needs here).
sources_of() { (cd "$1" && ls filter/common.cpp filter/voxel_grid.cpp filter/csnb.cpp filter/detail/*.cpp 2>/dev/null || true); }
objects=()
for side in old new; do
  root=$([[ $side == old ]] && echo "$work/old" || echo .)
  rename=$([[ $side == old ]] && echo -Dstvl=stvl_old || echo -DSTVL_AB_NEW)
  for f in $(sources_of "$root") "entry"; do
    src=$([[ $f == entry ]] && echo "$work/entry_$side.cpp" || echo "$root/$f")
    obj="$work/${side}_$(echo "$f" | tr / _).o"
    g++ "${flags[@]}" "$rename" -I"$root" -c "$src" -o "$obj"
    objects+=("$obj")
  done
done
g++ "${flags[@]}" -I. "-DFN_NAME=\"$fn\"" "$work/main.cpp" bench/cloud_io.cpp "${objects[@]}" \
  $([[ ${#tbb[@]} -gt 0 ]] && echo -ltbb) -o "$work/ab"
"$work/ab" "$cloud" "$voxel" "$threads" "$reps"
