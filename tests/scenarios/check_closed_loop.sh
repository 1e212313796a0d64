#!/usr/bin/env bash
# The closed loop end to end (issue 41). Usage: check_closed_loop.sh BIN OUT SCENARIOS_DIR
#  1. closed_loop_corridor cut to 6 s with a ROS 1 bag: /cmd_vel at the controller's 20 Hz, /plan at the planner's
#     1 Hz, both costmaps at their publish rates, as nav2 publishes them; navigation_success not evaluated (cut short).
#  2. the same seed gives the same drive: a second 6 s run's plans, events, path and map equal the first's.
#  3. goals refused at load (exit 2): in a wall (naming the nearest free cell), outside the map.
#  4. the occluded box's twin in closed loop: with STVL's frustum clearing the robot drives into something it did not
#     see or touches the cart (measured: a collision with the cart at 3.87 s and a plan through the box's 10 cells);
#     with ray-cast clearing (the scenario's) it touches nothing.
#  5. the no-return phantom's twin in the doorway (phantom_in_doorway.yaml): without clear_on_no_return (STVL's
#     behaviour) a planning cycle is blocked by the person's old place while the truth is free, and the controller
#     stops before it (measured: the cycles at 3 and 5 s, 107 and 81 named cells; a controller failure at 13.35 s,
#     goal at 25.65 s after 2 recoveries); with it neither (goal at 21.35 s).
#  6. a nav2 map in closed loop (office_floor_map.yaml): the global costmap is the map as nav2's StaticLayer reads it
#     (its 200 x 120 cells at 0.05 m from (-1, -2), the unknown corner kept unknown: -1 in the bag's OccupancyGrid),
#     and the drive reaches the planned path's end.
set -euo pipefail
bin=$1 out=$2 scenarios=$3
rm -rf "$out" && mkdir -p "$out"
"$bin" run "$scenarios/closed_loop_corridor.yaml" --duration 6 --bag "$out/run.bag" --out "$out/bag" --no-progress \
  >"$out/bag.log" 2>&1
/usr/bin/python3 - "$out/run.bag" "$out/bag/metrics.json" <<'PY'
import collections, json, sys
import rosbag
counts, types = collections.Counter(), {}
for topic, msg, t in rosbag.Bag(sys.argv[1]).read_messages(
        topics=["/plan", "/cmd_vel", "/local_costmap/costmap", "/global_costmap/costmap"]):
    counts[topic] += 1
    types[topic] = msg._type
    if topic == "/plan":
        assert msg.header.frame_id == "map" and len(msg.poses) > 100, "a plan in map with its poses"
        assert abs(msg.poses[-1].pose.position.x - 21.0) < 0.1, "the plan ends at the goal"
expected = {"/cmd_vel": ("geometry_msgs/Twist", 115, 125), "/plan": ("nav_msgs/Path", 6, 7),
            "/local_costmap/costmap": ("nav_msgs/OccupancyGrid", 12, 13),
            "/global_costmap/costmap": ("nav_msgs/OccupancyGrid", 6, 7)}
for topic, (kind, low, high) in expected.items():
    assert types.get(topic) == kind, f"{topic}: {types.get(topic)}"
    assert low <= counts[topic] <= high, f"{topic}: {counts[topic]} messages in 6 s, expected {low}..{high}"
m = json.load(open(sys.argv[2]))
status = {c["name"]: c["status"] for c in m["checks"]}
assert status["navigation_success"] == "not_evaluated", status
assert m["navigation"]["plans"] >= 6 and not m["navigation"]["success"]
print("PASS: the bag carries the drive as nav2 publishes it:", dict(counts))
PY
"$bin" run "$scenarios/closed_loop_corridor.yaml" --duration 6 --out "$out/again" --no-progress >"$out/again.log" 2>&1
cmp "$out/bag/map.ply" "$out/again/map.ply"
/usr/bin/python3 - "$out/bag/metrics.json" "$out/again/metrics.json" <<'PY'
import json, sys
a, b = (json.load(open(p))["navigation"] for p in sys.argv[1:3])
for key in ("planning_cycles", "events", "path_length_m", "min_clearance_m", "stalls", "collisions"):
    assert a[key] == b[key], f"{key} differs between two runs of the same seed"
print("PASS: the same seed, the same drive:", a["plans"], "plans,", round(a["path_length_m"], 6), "m")
PY
expect_refused() {  # NAME MESSAGE -- run arguments...
  local name=$1 message=$2 rc=0
  shift 3
  "$bin" run "$scenarios/closed_loop_corridor.yaml" --out "$out/$name" --no-progress "$@" >"$out/$name.log" 2>&1 || rc=$?
  if ((rc != 2)) || ! grep -q "$message" "$out/$name.log"; then
    echo "FAIL: $name: exit $rc, expected 2 and '$message'"; cat "$out/$name.log"; exit 1
  fi
  echo "PASS: $name refused: $(grep -o "navigation.goal.*" "$out/$name.log" | head -1)"
}
expect_refused goal_in_wall "the nearest free cell is" -- --set 'navigation.goal=[5.0,1.15,0]'
expect_refused goal_outside "lies outside the map" -- --set 'navigation.goal=[60.0,0.0,0]'
twin() {  # SCENARIO NAME EXPECT -- run arguments...
  local scenario=$1 name=$2 expect=$3 rc=0
  shift 4
  "$bin" run "$scenarios/$scenario" --out "$out/$name" --no-progress "$@" >"$out/$name.log" 2>&1 || rc=$?
  if ((rc == 2)); then echo "FAIL: $name refused"; cat "$out/$name.log"; exit 1; fi
  /usr/bin/python3 - "$out/$name/metrics.json" "$expect" "$name" <<'PY'
import json, sys
n = json.load(open(sys.argv[1]))["navigation"]
ok = eval(sys.argv[2], {"n": n})
print(f"{'PASS' if ok else 'FAIL'}: {sys.argv[3]}: {sys.argv[2]}: collisions {n['collisions']}, "
      f"{n['unseen_cycles']} cycles into the unseen, {n['blocked_cycles']} blocked by phantoms, {n['outcome']}")
sys.exit(0 if ok else 1)
PY
}
cart=(--set navigation.mode=closed_loop --set 'navigation.goal=[4.0,0.0,0.0]' --set duration_s=60)
twin cart_crossing.yaml occlusion_stvl "len(n['collisions']) + n['unseen_cycles'] >= 1" -- "${cart[@]}" \
  --set map.clearing_mode=frustum --set map.costmap_timing=stvl
twin cart_crossing.yaml occlusion_ours "n['success'] and len(n['collisions']) == 0" -- "${cart[@]}"
controller_failures="sum(e['kind'] == 'controller_failed' for e in n['events'])"
twin phantom_in_doorway.yaml doorway_stvl "n['blocked_cycles'] >= 1 and $controller_failures >= 1" -- \
  --set map.observation.clear_on_no_return=false
twin phantom_in_doorway.yaml doorway_ours "n['success'] and n['blocked_cycles'] == 0 and $controller_failures == 0" --
"$bin" run "$scenarios/office_floor_map.yaml" --set navigation.mode=closed_loop --bag "$out/map.bag" \
  --bag-topics /global_costmap/costmap --out "$out/map" --no-progress >"$out/map.log" 2>&1
/usr/bin/python3 - "$out/map.bag" "$out/map/metrics.json" <<'PY'
import json, sys
import rosbag
grids = [m for _, m, _ in rosbag.Bag(sys.argv[1]).read_messages(topics=["/global_costmap/costmap"])]
assert grids, "no global costmap in the bag"
g = grids[0]
i = g.info
assert (i.width, i.height) == (200, 120) and abs(i.resolution - 0.05) < 1e-6, (i.width, i.height, i.resolution)
assert abs(i.origin.position.x + 1.0) < 1e-6 and abs(i.origin.position.y + 2.0) < 1e-6, i.origin.position
unknown = sum(1 for v in g.data if v == -1)
assert unknown > 100, f"the map's unknown corner: {unknown} unknown cells"
n = json.load(open(sys.argv[2]))["navigation"]
assert n["success"], n["outcome"]
print(f"PASS: nav2 map in closed loop: global costmap {i.width} x {i.height} from the map, {unknown} unknown cells; "
      f"{n['outcome']}")
PY
# The bags are deleted once the checks pass (hundreds of MB; CI disk); a failing run keeps them.
rm -f "$out"/*.bag
