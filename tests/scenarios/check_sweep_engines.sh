#!/usr/bin/env bash
# stvl-bench sweep with the real engines: a 2 x 2 grid (voxel size x seed, 0.4 s runs) run here with --jobs, then
# emitted for GNU parallel and for CTest and run by them; every point must leave its metrics.json with its own
# settings, and --collect must see every point passed; the same with a twin per point. Bad grids exit 2 before anything
# runs.
set -euo pipefail
bin=$1 out=$2 scenario=$3
rm -rf "$out" && mkdir -p "$out"
grid=(--set duration_s=0.4 --set stop_at_path_end=false --set 'checks={}' --option voxel-size=0.05,0.1 --seeds 1..2)
fail() { echo "FAIL: $*"; exit 1; }

check_points() {  # DIR: the four points ran with their own voxel size and seed, and --collect saw them pass
  local dir=$1
  "$bin" sweep --collect "$dir" >/dev/null
  /usr/bin/python3 "$(dirname "$0")/check_sweep_points.py" "$dir" 4
}

"$bin" sweep "$scenario" "${grid[@]}" --jobs 2 --out "$out/local" >"$out/local.log" || fail "local sweep: $(cat "$out/local.log")"
check_points "$out/local"

# Each point with a twin on its drive (ray-cast clearing) into a sweep folder of its own: both folders' points pass
# with their own voxel size and seed, and each ran its own clearing.
"$bin" sweep "$scenario" "${grid[@]}" --jobs 2 --out "$out/with_twin" --twin "$out/twin;map.clearing_mode=raycast" \
  >"$out/with_twin.log" || fail "sweep with a twin: $(cat "$out/with_twin.log")"
check_points "$out/with_twin"
check_points "$out/twin"
for m in "$out"/with_twin/0*/metrics.json; do grep -q '"clearing_mode": "frustum"' "$m" || fail "$m: not frustum"; done
for m in "$out"/twin/0*/metrics.json; do grep -q '"clearing_mode": "raycast"' "$m" || fail "$m: not raycast"; done

if command -v parallel >/dev/null; then
  "$bin" sweep "$scenario" "${grid[@]}" --emit parallel --out "$out/parallel" >/dev/null
  parallel --will-cite --jobs 2 <"$out/parallel/jobs.txt" >"$out/parallel.log" 2>&1 || fail "GNU parallel: $(tail "$out/parallel.log")"
  check_points "$out/parallel"
else
  fail "GNU parallel is not installed (scripts/install-deps.sh installs it)"
fi

"$bin" sweep "$scenario" "${grid[@]}" --emit ctest --out "$out/ctest" >/dev/null
ctest --test-dir "$out/ctest" -j2 >"$out/ctest.log" 2>&1 || fail "ctest: $(tail "$out/ctest.log")"
grep -q "100% tests passed, 0 tests failed out of 4" "$out/ctest.log" || fail "ctest did not run 4 tests: $(tail "$out/ctest.log")"
check_points "$out/ctest"

"$bin" sweep "$scenario" "${grid[@]}" --emit slurm --out "$out/slurm" >/dev/null
grep -q "^#SBATCH --array=0-3$" "$out/slurm/sweep.sbatch" || fail "the Slurm array does not cover 4 points"

expect_bad() {  # EXPECTED-TEXT ARGS...: exit 2 and the text, nothing run
  local text=$1; shift
  local rc=0 log
  log=$("$bin" sweep "$@" 2>&1) || rc=$?
  ((rc == 2)) || fail "sweep $* exited $rc, expected 2: $log"
  grep -qF -- "$text" <<<"$log" || fail "sweep $*: expected '$text' in: $log"
}
expect_bad "--set map.voxel_sze=0.05: unknown key; did you mean 'voxel_size'?" "$scenario" --set map.voxel_sze=0.05,0.1 --out "$out/bad"
expect_bad "--set duration_s=abc: expected a number" "$scenario" --set duration_s=1,abc --out "$out/bad"
expect_bad "--set duration_s=: empty value in the list" "$scenario" --set duration_s= --out "$out/bad"
expect_bad "an empty grid" "$scenario" --out "$out/bad"
expect_bad "--option voxel-size=x: expected a number" "$scenario" --option voxel-size=x --out "$out/bad"
expect_bad "no sweep.json" --collect "$out"
[[ ! -e "$out/bad" ]] || fail "a rejected sweep left $out/bad behind"
echo "PASS: sweep runs here, under GNU parallel and under CTest; bad grids exit 2"
