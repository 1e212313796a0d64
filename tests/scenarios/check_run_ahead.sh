#!/usr/bin/env bash
# Running ahead (frames k + 1 and k + 2 made on two threads while frame k updates the layer and is evaluated)
# changes no output: for the default scenario with its bag, a run stopped at its path's end (the pipeline has made
# frames past it), three cameras drawn together, one stopped just before an outage, and a generated office with
# walking people (the truth moves), the metrics (timings aside), map.ply, costmap.pgm and the bag are byte for byte
# those of --no-run-ahead.
set -euo pipefail
bin=$1 scenarios=$2 out=$3
rm -rf "$out" && mkdir -p "$out"
strip_timing() {
  /usr/bin/python3 -c 'import json,sys; m=json.load(open(sys.argv[1]))
for k in ("timing_ms","wall_time_s","real_time_factor"): m.pop(k)
print(json.dumps(m, sort_keys=True))' "$1"
}
"$bin" world generate --seed 1 --out "$out/world" >"$out/world.log" 2>&1 || { echo "FAIL: world generate"; cat "$out/world.log"; exit 1; }
check() {  # name, then the run's arguments
  local name=$1; shift
  local bag_ahead=() bag_serial=()
  if [[ -n "${BAG:-}" ]]; then bag_ahead=(--bag "$out/$name.ahead.bag"); bag_serial=(--bag "$out/$name.serial.bag"); fi
  "$bin" run "$@" "${bag_ahead[@]}" --out "$out/$name.ahead" --no-progress >"$out/$name.ahead.log" 2>&1 || true
  "$bin" run "$@" "${bag_serial[@]}" --out "$out/$name.serial" --no-progress --no-run-ahead \
    >"$out/$name.serial.log" 2>&1 || true
  for side in ahead serial; do
    [[ -f "$out/$name.$side/metrics.json" ]] || { echo "FAIL: $name ($side) wrote no metrics"; cat "$out/$name.$side.log"; exit 1; }
  done
  [[ "$(strip_timing "$out/$name.ahead/metrics.json")" == "$(strip_timing "$out/$name.serial/metrics.json")" ]] ||
    { echo "FAIL: $name: metrics differ with and without running ahead"; exit 1; }
  for file in map.ply costmap.pgm; do
    cmp "$out/$name.ahead/$file" "$out/$name.serial/$file" || { echo "FAIL: $name: $file differs"; exit 1; }
  done
  echo "$name: same metrics, map and costmap ($(grep -o 'real-time factor [0-9.]*' "$out/$name.ahead.log") ahead," \
       "$(grep -o 'real-time factor [0-9.]*' "$out/$name.serial.log") one after another)"
}
BAG=1 check default "$scenarios/office_corridor.yaml" --duration 3
cmp "$out/default.ahead.bag" "$out/default.serial.bag" || { echo "FAIL: default: the bag differs"; exit 1; }
rm -f "$out"/default.*.bag
check path_end "$scenarios/office_corridor.yaml" --set 'robot.waypoints=[[0.0, 0.0], [1.0, 0.0]]'
grep -q '"path_completed"' "$out/path_end.ahead/metrics.json" || { echo "FAIL: path_end has no path_completed check"; exit 1; }
/usr/bin/python3 -c 'import json,sys; m=json.load(open(sys.argv[1])); assert m["sim_time_s"] < 10, m["sim_time_s"]' \
  "$out/path_end.ahead/metrics.json" || { echo "FAIL: path_end did not stop at the path's end"; exit 1; }
check three_cameras "$scenarios/delivery_robot_3cams.yaml" --duration 3
# Stopped at the path's end just before a camera's outage: the frames made ahead skip into it; the counts reported
# are those at the last frame taken.
check outage_end "$scenarios/camera_outage.yaml" --set 'robot.waypoints=[[0.0, 0.0], [2.9, 0.0]]'
check generated "$out/world/scenario.yaml" --duration 8
echo "run ahead: every output as one frame after another"
