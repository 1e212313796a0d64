#!/usr/bin/env bash
# scenarios/nav2_stvl_tutorial.yaml (the STVL layer read from nav2's tutorial parameter file) and its native
# twin tests/scenarios/nav2_tutorial_native.yaml give the same metrics.json over the first 10 s (timings, the
# scenario's name and file, and the source's name aside); `stvl-bench run` prints the linter's findings first.
set -euo pipefail
bin=$1 out=$2 compare=$3
here=$(dirname "$0")
rm -rf "$out" && mkdir -p "$out/ros" "$out/native"
"$bin" run "$here/../../scenarios/nav2_stvl_tutorial.yaml" --duration 10 --out "$out/ros/run" --no-progress \
  >"$out/ros.log" || true
"$bin" run "$here/nav2_tutorial_native.yaml" --duration 10 --out "$out/native/run" --no-progress >/dev/null || true
grep -q "^lint: .*nav2_stvl_tutorial.yaml:52: stvl_layer.pointcloud.voxel_filter: " "$out/ros.log" ||
  { echo "FAIL: the run did not print the linter's voxel_filter finding"; cat "$out/ros.log"; exit 1; }
python3 "$compare" "$out/ros" "$out/native" --ignore scenario --ignore scenario_file \
  --ignore "cameras[0].sources[0].name" --ignore "evaluation.failure_modes.outage.cameras[0].sources[0].source"
