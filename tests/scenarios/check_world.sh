#!/usr/bin/env bash
# stvl-bench world end to end: writes a world and its scenario into OUT/world (`world generate ...` or `world
# from-map MAP`), runs that scenario and requires exit 0 with path_completed passed: the planned path is drivable
# to its end and every check the written scenario sets holds.
#   check_world.sh STVL_BENCH OUT generate|from-map ARGS...
set -euo pipefail
bin=$1 out=$2
shift 2
rm -rf "$out" && mkdir -p "$out"
"$bin" world "$@" --out "$out/world" >"$out/world.log" 2>&1 || { echo "FAIL: stvl-bench world $* exited $?"; cat "$out/world.log"; exit 1; }
for f in world.xml robot.xml scenario.yaml; do
  [[ -f "$out/world/$f" ]] || { echo "FAIL: $out/world/$f was not written"; exit 1; }
done
rc=0
"$bin" run "$out/world/scenario.yaml" --out "$out/run" --no-progress >"$out/run.log" 2>&1 || rc=$?
cat "$out/world.log"
grep -E "^(PASS|FAIL|SKIP)|real-time factor" "$out/run.log" || true
[[ $rc -eq 0 ]] || { echo "FAIL: the scenario's run exited $rc"; tail -n 20 "$out/run.log"; exit 1; }
grep -q "^PASS path_completed" "$out/run.log" || { echo "FAIL: no passed path_completed check"; exit 1; }
echo "PASS: $* ran to its path's end with every check passed"
