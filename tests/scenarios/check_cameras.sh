#!/usr/bin/env bash
# A short run of scenarios/delivery_robot_3cams.yaml with a bag: every camera's topics (image, camera_info,
# points, each in its own optical frame), its frames in /tf_static and its CameraInfo reprojection
# (tests/run/check_bag.py); recall and stage times per camera in metrics.json; every camera's depth frames in
# the report.
set -euo pipefail
bin=$1 out=$2 checker=$3
here=$(dirname "$0")
rm -rf "$out" && mkdir -p "$out"
"$bin" run "$here/../../scenarios/delivery_robot_3cams.yaml" --duration 2 --out "$out/run" --bag "$out/run.bag" \
  --no-progress >/dev/null || true
[[ -f "$out/run.bag" ]] || { echo "FAIL: run.bag missing"; exit 1; }
/usr/bin/python3 - "$out" <<'PY'
import json, os, sys
out = sys.argv[1]
cams = ["front_camera", "left_camera", "right_camera"]
m = json.load(open(os.path.join(out, "run/metrics.json")))
topics, edges, reprojection = {}, [["map", "odom"], ["odom", "base_link"]], []
for c in cams:
    frame = c + "_depth_optical_frame"
    for what, ty in (("image_rect_raw", "sensor_msgs/Image"), ("camera_info", "sensor_msgs/CameraInfo"),
                     ("points", "sensor_msgs/PointCloud2")):
        topics["/%s/depth/%s" % (c, what)] = {"type": ty, "frame_id": frame, "count": 31}  # 2 s at 15 Hz
    topics["/stvl/%s/filtered_points" % c] = {"type": "sensor_msgs/PointCloud2", "frame_id": "map", "count": 31}
    edges += [["base_link", c + "_link"], [c + "_link", frame]]
    reprojection.append({"image": "/%s/depth/image_rect_raw" % c, "info": "/%s/depth/camera_info" % c,
                         "cloud": "/%s/depth/points" % c, "max_frames": 2})
# The robot's messages once per distinct time: the three cameras share their 31 frame times.
for t in ("/clock", "/tf", "/odom", "/ground_truth/pose"):
    topics[t] = {"count": 31}
json.dump({"topics": topics, "tf_edges": edges, "reprojection": reprojection}, open(os.path.join(out, "expect.json"), "w"))
fails = []
got = {c["name"]: c for c in m["evaluation"]["cameras"]}
if sorted(got) != sorted(cams): fails.append("evaluation.cameras: %s" % sorted(got))
for c in cams:
    if got.get(c, {}).get("final_observed_truth_voxels", 0) <= 0: fails.append("%s saw no truth voxel" % c)
    frames = m["timing_ms"]["per_camera"].get(c, {}).get("frames")
    if frames != 31: fails.append("%s: %s frames timed, expected 31" % (c, frames))
report = open(os.path.join(out, "run/report.html")).read()
for c in cams:
    if "<h3>%s</h3>" % c not in report: fails.append("report: no depth frames heading for " + c)
    if not any(f.startswith(c + "_depth_") for f in os.listdir(os.path.join(out, "run/frames"))):
        fails.append("frames/: no depth frame of " + c)
for f in fails: print("FAIL:", f)
sys.exit(1 if fails else 0)
PY
/usr/bin/python3 "$checker" "$out/run.bag" "$out/expect.json"
# The bag ends with the run's last map (the update of the last instant takes all three cameras; issue 28, 5):
# the last /stvl/voxel_grid holds map.ply's voxels exactly.
/usr/bin/python3 - "$out/run.bag" "$out/run/map.ply" <<'PY'
import struct, sys
import rosbag
last = None
for _, msg, _ in rosbag.Bag(sys.argv[1]).read_messages(topics=["/stvl/voxel_grid"]):
    last = msg
def keys(points, size=0.05):
    return {tuple(int(round(c / size - 0.5)) for c in p) for p in points}
grid = [struct.unpack_from("<fff", last.data, i * last.point_step) for i in range(last.width * last.height)]
data = open(sys.argv[2], "rb").read()
end = data.index(b"end_header\n") + len(b"end_header\n")
count = int([l for l in data[:end].decode().splitlines() if l.startswith("element vertex")][0].split()[2])
stride = (len(data) - end) // max(count, 1)
ply = [struct.unpack_from("<fff", data, end + i * stride) for i in range(count)]
a, b = keys(grid), keys(ply)
print("bag's last voxel grid: %d voxels, map.ply: %d, in both: %d" % (len(a), len(b), len(a & b)))
sys.exit(0 if a == b and a else 1)
PY
# The bags are deleted once the checks pass (hundreds of MB; CI disk); a failing run keeps them.
rm -f "$out"/*.bag
