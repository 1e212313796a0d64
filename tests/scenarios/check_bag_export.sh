#!/usr/bin/env bash
# A short run of the default scenario exported as a bag: topics, types, counts per frame, frame ids, latching,
# increasing stamps, CameraInfo reprojection (tests/run/check_bag.py), `rosbag info`, the depth images
# equal to the frames `stvl-bench render` gives for the same scenario and seed, and the bag's last costmap equal
# to costmap.pgm (also for band_edge.yaml, whose band edge cuts a voxel).
set -euo pipefail
bin=$1 out=$2 checker=$3
rm -rf "$out" && mkdir -p "$out"
"$bin" run --duration 3 --out "$out/run" --bag "$out/run.bag" --bag-compression lz4 --no-progress >/dev/null || true
[[ -f "$out/run.bag" && ! -e "$out/run.bag.active" ]] || { echo "FAIL: run.bag missing or still .active"; exit 1; }
frames=$(/usr/bin/python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["frames"])' "$out/run/metrics.json")
/usr/bin/python3 - "$frames" "$out/expect.json" <<'PY'
import json, sys
n = int(sys.argv[1])
per_frame = {
    "/clock": ("rosgraph_msgs/Clock", None),
    "/tf": ("tf2_msgs/TFMessage", None),
    "/odom": ("nav_msgs/Odometry", "odom"),
    "/ground_truth/pose": ("geometry_msgs/PoseStamped", "map"),
    "/camera/depth/image_rect_raw": ("sensor_msgs/Image", "camera_depth_optical_frame"),
    "/camera/depth/camera_info": ("sensor_msgs/CameraInfo", "camera_depth_optical_frame"),
    "/camera/depth/points": ("sensor_msgs/PointCloud2", "camera_depth_optical_frame"),
    "/stvl/filtered_points": ("sensor_msgs/PointCloud2", "map"),
}
topics = {t: {"type": ty, "count": n, **({"frame_id": f} if f else {})} for t, (ty, f) in per_frame.items()}
topics["/tf_static"] = {"type": "tf2_msgs/TFMessage", "count": 1, "latched": True}
topics["/ground_truth/occupancy"] = {"type": "sensor_msgs/PointCloud2", "count": 1, "latched": True, "frame_id": "map"}
topics["/stvl/voxel_grid"] = {"type": "sensor_msgs/PointCloud2", "min_count": 1, "frame_id": "map"}
topics["/stvl/costmap"] = {"type": "nav_msgs/OccupancyGrid", "min_count": 1, "frame_id": "map"}
json.dump({"compression": "lz4", "only_listed_topics": True, "topics": topics,
           "tf_edges": [["map", "odom"], ["odom", "base_link"], ["base_link", "camera_link"],
                        ["camera_link", "camera_depth_optical_frame"]]}, open(sys.argv[2], "w"))
PY
/usr/bin/python3 "$checker" "$out/run.bag" "$out/expect.json"
"$bin" render --scenario "$(dirname "$0")/../../scenarios/office_corridor.yaml" --frames 3 --out "$out/render" >/dev/null
/usr/bin/python3 "$(dirname "$0")/compare_bag_depth.py" "$out/run.bag" "$out/render"
here=$(dirname "$0")
/usr/bin/python3 "$here/compare_bag_costmap.py" "$out/run.bag" "$out/run"
"$bin" run "$here/band_edge.yaml" --out "$out/band" --bag "$out/band.bag" --no-progress >/dev/null || true
/usr/bin/python3 "$here/compare_bag_costmap.py" "$out/band.bag" "$out/band"
# The bags are deleted once the checks pass (hundreds of MB; CI disk); a failing run keeps them.
rm -f "$out"/*.bag
