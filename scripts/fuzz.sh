#!/usr/bin/env bash
# Builds the libFuzzer targets (clang, ASan + UBSan, libraries instrumented too) into build-fuzz/ and runs each
# for a bounded time.
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]   default 60 s each; targets: scenario filter voxel_map
#                                                       depth_to_cloud urdf nav2_map ros2msg (default: all)
# The working corpus lives in build-fuzz/corpus/<target> (seeded from tests/fuzz/corpus/<target> and
# tests/regressions/<target>); crashes, leaks, timeouts and OOMs land in build-fuzz/artifacts/<target>/.
# To keep a crash: minimise it (build-fuzz/bin/fuzz_<target> -minimize_crash=1 -runs=10000 FILE), copy it to
# tests/regressions/<target>/, fix the code; ctest's regression_<target> then replays it in every build.
# SKIP_BUILD=1 reuses the binaries already in build-fuzz/. Exits 1 when any target found something, 2 when the build fails.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
seconds=${1:-60}
shift || true
build=${BUILD_DIR:-build-fuzz}
jobs=${JOBS:-$(nproc)}
all_targets=(scenario filter voxel_map depth_to_cloud urdf nav2_map ros2msg)
targets=("$@")
((${#targets[@]})) || targets=("${all_targets[@]}")

if [[ -z "${SKIP_BUILD:-}" ]]; then
command -v clang++ >/dev/null || { echo "fuzz.sh: clang++ not found (apt-get install clang libclang-rt-14-dev)" >&2; exit 2; }
flags="-O1 -g -fno-omit-frame-pointer -fsanitize=fuzzer-no-link,address,undefined -fno-sanitize-recover=undefined -fsanitize-ignorelist=$root/tests/sanitizers/ubsan_ignorelist.txt"
cmake -S . -B "$build" -DCMAKE_C_COMPILER=clang -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=FuzzDebug \
  -DCMAKE_CXX_FLAGS_FUZZDEBUG="$flags" -DCMAKE_C_FLAGS_FUZZDEBUG="$flags" \
  -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" -DSTVL_FUZZ=ON -DSTVL_CUDA=OFF >/dev/null
build_targets=()
for t in "${targets[@]}"; do build_targets+=(--target "fuzz_$t"); done
cmake --build "$build" -j"$jobs" "${build_targets[@]}" || exit 2
fi

export ASAN_OPTIONS="detect_leaks=1 ${ASAN_OPTIONS:-}"
export UBSAN_OPTIONS="print_stacktrace=1 halt_on_error=1 ${UBSAN_OPTIONS:-}"
found=()
for t in "${targets[@]}"; do
  corpus=$build/corpus/$t
  artifacts=$build/artifacts/$t
  mkdir -p "$corpus" "$artifacts"
  cp -n tests/fuzz/corpus/"$t"/* "$corpus"/ 2>/dev/null || true
  cp -n tests/regressions/"$t"/* "$corpus"/ 2>/dev/null || true
  # ROS 2's own .msg texts, where ../shared (beside the checkout) has them.
  [[ $t == ros2msg && -d ../shared/ros2_msgs ]] &&
    for f in ../shared/ros2_msgs/*/msg/*.msg; do cp -n "$f" "$corpus/ros2_$(basename "$(dirname "$(dirname "$f")")")_$(basename "$f")"; done
  extra=()
  [[ -f tests/fuzz/$t.dict ]] && extra+=(-dict="tests/fuzz/$t.dict")
  echo "== fuzz_$t for ${seconds}s"
  log=$build/fuzz_$t.log
  # -timeout: one input taking more than 10 s is a finding (a hang); -rss_limit_mb: so is using 2 GB.
  if "$build/bin/fuzz_$t" "$corpus" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=8192 \
       -print_final_stats=1 -artifact_prefix="$artifacts/" "${extra[@]}" >"$log" 2>&1; then
    grep -E "^stat::number_of_executed_units|^stat::peak_rss_mb" "$log" | tr '\n' ' '
    echo "corpus $(ls "$corpus" | wc -l) files: clean"
  else
    found+=("$t")
    grep -E "ERROR: |SUMMARY: |Test unit written to" "$log" | head -5
    echo "fuzz_$t FOUND SOMETHING: see $log and $artifacts/"
  fi
done
if ((${#found[@]})); then
  echo "fuzz.sh: findings in ${found[*]}"
  exit 1
fi
echo "fuzz.sh: ${#targets[@]} targets, ${seconds}s each, no findings"
