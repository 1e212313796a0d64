#!/usr/bin/env bash
# nav2's VoxelLayer and ObstacleLayer update written again in Python from navigation2's source (nav2_from_bag.py,
# nav2_layers.py), fed only the bag of a short run with map.layer_type nav2_voxel | nav2_obstacle, must rebuild the
# layer's last grid cell for cell (the bag's last /stvl/costmap) and, for the voxel layer, its marked voxels (the
# run's map.ply): the bag says what each cycle gathered, and the layer is nav2's. One case per argument:
#   voxel_corridor     office corridor, one camera, VoxelLayer with z_resolution 0.05 and 16 levels (1:1 voxels; the
#                      rays reach the map's top, clipped at jazzy's getSizeInMetersZ, (size_z - 1 + 0.5) *
#                      z_resolution: this case found the bench clipping at main's size_z * z_resolution)
#   voxel_coarse       the same with nav2's defaults z_resolution 0.2, z_voxels 10 (a voxel spans four bench voxels)
#   voxel_cameras      three cameras at one instant, VoxelLayer
#   voxel_ticks        a 15 Hz camera at a 4 Hz costmap (cycles at ticks between frames), observation_persistence 0.5
#   voxel_receding     a person walking away past obstacle_max_range 1.5 while within raytrace_max_range 1.5
#                      (navigation2 #5476's geometry), VoxelLayer
#   obstacle_corridor  office corridor, ObstacleLayer (marking rule #5697 + #6092, nav2 main today)
#   obstacle_cameras   three cameras, ObstacleLayer
#   obstacle_receding_pre_5697, obstacle_receding_5697, obstacle_receding_6092
#                      the walking person, ObstacleLayer with each marking rule: 3D squared distance (before #5697),
#                      cell distance (#5697), 2D world pre-filter + cell distance (#6092)
#   voxel_reversing, obstacle_reversing_pre_5697, obstacle_reversing_6092
#                      the robot driving in reverse (robot.reverse) away from the corridor's obstacles past
#                      obstacle_max_range 1.5 = raytrace_max_range (#5476 as reported), VoxelLayer and ObstacleLayer
#   voxel_footprint    the robot that sees its own bumper on a 2 m drive, VoxelLayer with a footprint: updateFootprint
#                      and updateCosts' setConvexPolygonCost(footprint, FREE_SPACE) at every cycle
# Exit 0 agree, 1 disagree, 2 bad input, 77 skipped (no rosbag for /usr/bin/python3).
set -euo pipefail
case=$1 bin=$2 src=$3 out=$4
if ! /usr/bin/python3 -c 'import rosbag' 2>/dev/null; then
  echo "SKIP: /usr/bin/python3 has no rosbag (python3-rosbag)"
  exit 77
fi
rm -rf "$out" && mkdir -p "$out"
corridor=("$src/scenarios/office_corridor.yaml" --duration 4)
cameras=("$src/scenarios/delivery_robot_3cams.yaml" --duration 4)
receding=("$src/scenarios/person_walks_away.yaml" --duration 6 --set map.observation.obstacle_max_range=1.5
          --set map.observation.raytrace_max_range=1.5)
# The robot backing away (robot.reverse) from the corridor's obstacles ahead past obstacle_max_range 1.5 while they
# stay within raytrace_max_range 1.5: navigation2 #5476 as reported (a reversing robot).
reversing=("$src/scenarios/office_corridor.yaml" --duration 9 --set 'robot.start=[7.0, 0.0, 0.0]'
           --set 'robot.waypoints=[[7.0, 0.0], [3.0, 0.0]]' --set robot.reverse=true
           --set map.observation.obstacle_max_range=1.5 --set map.observation.raytrace_max_range=1.5)
voxel=(--set map.layer_type=nav2_voxel)
obstacle=(--set map.layer_type=nav2_obstacle)
case $case in
  voxel_corridor) args=("${corridor[@]}" "${voxel[@]}" --set map.nav2_layer.z_resolution=0.05
                        --set map.nav2_layer.z_voxels=16) ;;
  voxel_coarse) args=("${corridor[@]}" "${voxel[@]}" --set map.nav2_layer.z_resolution=0.2
                      --set map.nav2_layer.z_voxels=10) ;;
  voxel_cameras) args=("${cameras[@]}" "${voxel[@]}") ;;
  voxel_ticks) args=("${corridor[@]}" "${voxel[@]}" --set map.update_frequency=4
                     --set map.observation.observation_persistence=0.5) ;;
  voxel_receding) args=("${receding[@]}" "${voxel[@]}") ;;
  voxel_reversing) args=("${reversing[@]}" "${voxel[@]}") ;;
  voxel_footprint) args=("$src/scenarios/robot_sees_itself_driving.yaml" --duration 3 "${voxel[@]}") ;;
  obstacle_corridor) args=("${corridor[@]}" "${obstacle[@]}") ;;
  obstacle_cameras) args=("${cameras[@]}" "${obstacle[@]}") ;;
  obstacle_receding_pre_5697 | obstacle_receding_5697 | obstacle_receding_6092)
    args=("${receding[@]}" "${obstacle[@]}" --set "map.nav2_layer.nav2_marking_range=${case#obstacle_receding_}") ;;
  obstacle_reversing_pre_5697 | obstacle_reversing_6092)
    args=("${reversing[@]}" "${obstacle[@]}" --set "map.nav2_layer.nav2_marking_range=${case#obstacle_reversing_}") ;;
  *) echo "unknown case $case" >&2; exit 2 ;;
esac
# The run's own checks may fail on a cut-short run; only its outputs matter here. The bag keeps what the checker reads.
"$bin" run "${args[@]}" --out "$out/run" --bag "$out/run.bag" --no-progress \
  --bag-topics '/tf,/tf_static,/stvl/*filtered_points,/stvl/costmap' >"$out/run.log" 2>&1 || true
if [[ ! -f "$out/run.bag" || ! -f "$out/run/map.ply" ]]; then
  echo "FAIL: the run left no bag or map"
  cat "$out/run.log"
  exit 1
fi
/usr/bin/python3 "$(dirname "$0")/nav2_from_bag.py" "$out/run.bag" "$out/run/metrics.json" "$out/run/map.ply" \
  --min-agreement 1.0
