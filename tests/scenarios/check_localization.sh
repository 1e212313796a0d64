#!/usr/bin/env bash
# Localization as a failure end to end (issue 43). Usage: check_localization.sh BIN OUT SCENARIOS_DIR
#  1. localization_jump as shipped (the layer in odom, the local costmap's frame): the jump costs it nothing; its
#     checks pass (exit 0) and the bag's map -> odom carries the localizer's jump (0.3 m between 7.9 and 8.1 s).
#  2. the same run in map (the global costmap's frame): the walls seen while the estimate was 0.3 m off are marked
#     there (measured: F1 0.989 -> 0.852, costmap precision 0.921 -> 0.850, accuracy p90 0.025 -> 0.226 m, 4 lethal
#     cells where the truth is free on the path); required: F1 and precision at least 0.05 lower, p90 at
#     least 0.15 m higher, a free cell on the path lethal, the run failed (exit 1).
#  3. the localizer's noise alone (no jump, in map) smears but does not fail (measured: precision 0.939, p90 0.056 m):
#     precision within 0.03 of the odom run's, p90 below 0.15 m.
#  4. the same seed gives the same corrections and map; 5. bad localization values: exit 2 naming key and line.
set -euo pipefail
bin=$1 out=$2 scenarios=$3
rm -rf "$out" && mkdir -p "$out"
run() {  # NAME -- args... ; exit code in $rc
  local name=$1
  shift 2
  rc=0
  "$bin" run "$scenarios/localization_jump.yaml" --out "$out/$name" --no-progress "$@" >"$out/$name.log" 2>&1 || rc=$?
}
run odom -- --bag "$out/odom.bag" --bag-topics /tf,/ground_truth/pose
((rc == 0)) || { echo "FAIL: localization_jump as shipped exited $rc"; cat "$out/odom.log"; exit 1; }
run map -- --set localization.global_frame=map
((rc == 1)) || { echo "FAIL: localization_jump in map exited $rc, expected 1"; exit 1; }
run noise -- --set localization.global_frame=map --set 'localization.jumps=[]'
/usr/bin/python3 - "$out" <<'PY'
import json, sys
m = {k: json.load(open(f"{sys.argv[1]}/{k}/metrics.json")) for k in ("odom", "map", "noise")}
ev = {k: v["evaluation"] for k, v in m.items()}
f1 = {k: e["mean"]["f1"] for k, e in ev.items()}
cp = {k: e["mean"]["costmap_precision"] for k, e in ev.items()}
p90 = {k: e["accuracy_m"]["p90"] for k, e in ev.items()}
lethal = {k: e["mean"]["max_path_free_lethal"] for k, e in ev.items()}
for k in m:
    print(f"{k}: F1 {f1[k]:.3f}, costmap precision {cp[k]:.3f}, p90 {p90[k]:.3f} m, free path cells lethal {lethal[k]}, "
          f"localization {m[k]['localization']['mean_error_m']:.3f} m mean, {m[k]['localization']['jumps']} jumps")
assert m["map"]["localization"]["jumps"] == 2 and m["map"]["localization"]["max_error_m"] > 0.25
assert f1["map"] <= f1["odom"] - 0.05 and cp["map"] <= cp["odom"] - 0.05, "a jump in map must cost the map"
assert p90["map"] >= p90["odom"] + 0.15, "the walls seen during the jump must be marked off the surfaces"
assert lethal["map"] >= 1 and lethal["odom"] == 0, "the jump's walls must block the path; in odom nothing"
assert abs(cp["noise"] - cp["odom"]) <= 0.03 and p90["noise"] < 0.15, "the localizer's noise alone smears a little"
print("PASS: a localization jump marks the global costmap's walls off their surfaces; the odom layer keeps them")
PY
/usr/bin/python3 - "$out/odom.bag" <<'PY'
import math, sys
import rosbag
def planar(tr):  # (x, y, yaw) of a geometry_msgs Transform or Pose
    t = getattr(tr, "translation", None) or tr.position
    q = getattr(tr, "rotation", None) or tr.orientation
    return t.x, t.y, 2.0 * math.atan2(q.z, q.w)
def compose(a, b):
    c, s = math.cos(a[2]), math.sin(a[2])
    return a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2]
truth, estimate = {}, {}
for topic, msg, _ in rosbag.Bag(sys.argv[1]).read_messages(topics=["/tf", "/ground_truth/pose"]):
    if topic == "/ground_truth/pose":
        truth[msg.header.stamp.to_nsec()] = planar(msg.pose)
    else:
        edges = {(tr.header.frame_id, tr.child_frame_id): tr for tr in msg.transforms}
        if ("map", "odom") in edges and ("odom", "base_link") in edges:
            stamp = edges[("map", "odom")].header.stamp.to_nsec()
            estimate[stamp] = compose(planar(edges[("map", "odom")].transform),
                                      planar(edges[("odom", "base_link")].transform))
start = min(truth)  # the bag's clock starts at the run's t = 0
errors = [((t - start) * 1e-9, math.hypot(estimate[t][0] - truth[t][0], estimate[t][1] - truth[t][1]))
          for t in sorted(estimate) if t in truth]
off = [t for t, e in errors if e > 0.2]
print(f"bag: {len(errors)} poses map -> odom -> base_link against the truth; off by over 0.2 m from {min(off):.2f} to "
      f"{max(off):.2f} s ({len(off)} poses)")
assert 7.9 <= min(off) <= 8.2 and 19.8 <= max(off) < 20.0, (min(off), max(off))
assert sum(1 for t, _ in errors if 8.2 <= t < 19.8) <= len(off) + 1, "the estimate stays off during the jump"
print("PASS: the bag's map -> odom is the localizer's, its jump included")
PY
run once -- --duration 5 --set 'localization.jumps=[]'
run twice -- --duration 5 --set 'localization.jumps=[]'
cmp "$out/once/map.ply" "$out/twice/map.ply"
/usr/bin/python3 -c 'import json,sys; a,b=(json.load(open(p))["localization"] for p in sys.argv[1:3]); assert a==b, (a,b)' \
  "$out/once/metrics.json" "$out/twice/metrics.json"
echo "PASS: same seed, same corrections and map"
# 6. closed loop (nav2's frames: the local costmap in odom, the global costmap and the plan in map): the doorway twin
#    with the localizer 0.3 m off across the corridor from 1 s; the plan through the 0.9 m doorway, followed through
#    the estimate, runs the robot at the door frame, and from the wrong pose the planner mostly finds no way (measured:
#    no plan after 6 recoveries at 29.0 s, stalled 18.6 s, exit 1); with the noise alone the drive is the shipped one
#    (goal at 21.30 s; 21.35 s without localization).
doorway() {  # NAME Y_M
  sed "s#\.\./worlds/#$scenarios/../worlds/#" "$scenarios/phantom_in_doorway.yaml" >"$out/$1.yaml"
  printf 'localization:\n  rate_hz: 10\n  noise_xy_m: 0.02\n  noise_yaw_rad: 0.009\n  jumps: [{at_s: 1.0, y_m: %s}]\n' "$2" \
    >>"$out/$1.yaml"
  rc=0
  "$bin" run "$out/$1.yaml" --out "$out/$1" --no-progress >"$out/$1.log" 2>&1 || rc=$?
}
doorway door_noise 0.0
((rc == 0)) || { echo "FAIL: the doorway with the localizer's noise alone exited $rc"; cat "$out/door_noise.log"; exit 1; }
doorway door_jump 0.3
((rc == 1)) || { echo "FAIL: the doorway with a 0.3 m jump exited $rc, expected 1"; exit 1; }
/usr/bin/python3 - "$out" <<'PY'
import json, sys
m = {k: json.load(open(f"{sys.argv[1]}/{k}/metrics.json")) for k in ("door_noise", "door_jump")}
n = {k: v["navigation"] for k, v in m.items()}
for k in n:
    print(f"{k}: {n[k]['outcome'][:90]}; {n[k]['recoveries']} recoveries, stalled {n[k]['stalled_s']:.2f} s, "
          f"localization {m[k]['localization']['mean_error_m']:.3f} m mean in {m[k]['localization']['global_frame']}")
assert n["door_noise"]["success"] and n["door_noise"]["time_to_goal_s"] < 25, n["door_noise"]["outcome"]
assert not n["door_jump"]["success"] and n["door_jump"]["recoveries"] >= 1 and n["door_jump"]["stalled_s"] > 2.0
assert m["door_jump"]["localization"]["global_frame"] == "odom", "closed loop: the run's layer is the local costmap's"
off = float(n["door_jump"]["outcome"].split("the localizer was ")[1].split(" m")[0])
assert 0.2 <= off <= 0.4, f"the failure names the localizer's error: {n['door_jump']['outcome']}"
print("PASS: in closed loop the localizer's jump stalls the robot at the doorway; its noise alone does not")
PY
expect_bad() {  # KEY -- sets...
  local key=$1
  shift 2
  run bad -- --duration 1 "$@"
  if ((rc != 2)) || ! grep -q "$key" "$out/bad.log"; then
    echo "FAIL: expected exit 2 naming $key, got $rc:"; cat "$out/bad.log"; exit 1
  fi
  echo "PASS: refused: $(grep -m1 "$key" "$out/bad.log")"
}
expect_bad rate_hz -- --set localization.rate_hz=0
expect_bad noise_xy_m -- --set localization.noise_xy_m=.nan
expect_bad noise_yaw_rad -- --set localization.noise_yaw_rad=-0.1
expect_bad global_frame -- --set localization.global_frame=base_link
expect_bad at_s -- --set 'localization.jumps[0].at_s=80'
expect_bad at_s -- --set 'localization.jumps[1].at_s=5'
expect_bad x_m -- --set 'localization.jumps[0].x_m=.inf'
expect_bad noise_xy -- --set localization.noise_xy=0.1
# From a file the message names the line of the jump.
sed "s/- {at_s: 20.0}/- {at_s: 90.0}/; s#\.\./worlds/#$scenarios/../worlds/#" "$scenarios/localization_jump.yaml" >"$out/bad.yaml"
rc=0
"$bin" run "$out/bad.yaml" --out "$out/bad_file" --no-progress >"$out/bad_file.log" 2>&1 || rc=$?
((rc == 2)) && grep -q "bad.yaml:[0-9]*: localization.jumps\[1\].at_s: .*not within the run" "$out/bad_file.log" ||
  { echo "FAIL: a jump past the run's end: exit $rc"; cat "$out/bad_file.log"; exit 1; }
echo "PASS: refused: $(cat "$out/bad_file.log")"
rm -f "$out"/*.bag
