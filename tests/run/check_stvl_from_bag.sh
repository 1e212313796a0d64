#!/usr/bin/env bash
# STVL's update written again in Python from STVL's source (stvl_from_bag.py), fed only the bag of a short run,
# must rebuild the run's map voxel for voxel (every time within 1 us) and its last costmap: the bag says what the
# map took, and the map is STVL's. One case per argument: corridor (one camera), nav2 (the nav2 tutorial's
# parameter file: separate marking and clearing sources, 5 Hz updates, footprint), cameras (three cameras at one
# instant), persistence (observation_persistence 0.5 s, exponential decay, a person walking away), ticks (a 15 Hz
# camera at a 4 Hz costmap: updates at ticks between frames), outage (three cameras at 5 Hz, the front one stopped
# from 5 to 8 s: every tick applies its last reading again), lidar (STVL's 3D lidar model, model_type 1, in the
# camera's link frame, full circle, padded), relative (the band and the voxel leaves in base_link, STVL's voxel_relative, up a ramp).
set -euo pipefail
case=$1 bin=$2 src=$3 out=$4
/usr/bin/python3 -c 'import rosbag' 2>/dev/null || { echo "SKIP: /usr/bin/python3 has no rosbag (python3-rosbag)"; exit 77; }
rm -rf "$out" && mkdir -p "$out"
case $case in
  corridor) args=("$src/scenarios/office_corridor.yaml" --duration 4) ;;
  nav2) args=("$src/scenarios/nav2_stvl_tutorial.yaml" --duration 5) ;;
  cameras) args=("$src/scenarios/delivery_robot_3cams.yaml" --duration 4) ;;
  persistence) args=("$src/scenarios/person_walks_away.yaml" --duration 6 --set map.clearing_mode=frustum
                     --set map.costmap_timing=stvl
                     --set map.observation.clear_on_no_return=false --set map.observation.decay_acceleration=5
                     --set map.observation.observation_persistence=0.5 --set map.decay_model=exponential
                     --set map.voxel_decay=4) ;;
  ticks) args=("$src/scenarios/office_corridor.yaml" --duration 4 --set map.update_frequency=4) ;;
  outage) args=("$src/scenarios/camera_outage.yaml" --duration 9 --set map.update_frequency=5) ;;
  lidar) args=("$src/scenarios/person_walks_away.yaml" --duration 6 --set map.clearing_mode=frustum
                --set map.costmap_timing=stvl
                --set map.observation.clear_on_no_return=false --set map.observation.model_type=1
                --set map.observation.sensor_frame=link --set map.observation.horizontal_fov_angle=6.2832
                --set map.observation.vertical_fov_angle=0.6 --set map.observation.vertical_fov_padding=0.05
                --set map.observation.decay_acceleration=5) ;;
  relative) args=("$src/scenarios/ramp_platform.yaml" --duration 10) ;;
  *) echo "unknown case $case" >&2; exit 2 ;;
esac
# The run's own checks may fail on a cut-short run; only its outputs matter here.
# Only what the rebuild reads goes in the bag (the full clouds would take gigabytes of CI disk).
"$bin" run "${args[@]}" --out "$out/run" --bag "$out/run.bag" --no-progress \
  --bag-topics '/tf,/tf_static,/stvl/*filtered_points,/stvl/costmap' >"$out/run.log" 2>&1 || true
[[ -f "$out/run.bag" && -f "$out/run/map.ply" ]] || { echo "FAIL: the run left no bag or map"; cat "$out/run.log"; exit 1; }
/usr/bin/python3 "$(dirname "$0")/stvl_from_bag.py" "$out/run.bag" "$out/run/metrics.json" "$out/run/map.ply" \
  --min-agreement 1.0
