#!/usr/bin/env bash
# stvl-bench replay on real and bench-written recordings: check_replay.sh CASE STVL_BENCH SOURCE_DIR OUT_DIR.
#   d435       the real D435 bag (shared/realdata): frames, intrinsics and valid pixels as python3-rosbag reads
#              them; the map's voxel count between the bounds expected_replay_voxels.py computes on its own
#   kinect     the real Kinect PNG frames with their rtabmap calibration (base_link -> camera)
#   roundtrip  a run's own bag replays to the run's map (voxel sets agree >= 99 %), and the replay's re-exported
#              bag replays to the same map again
# Exit 0 pass, 1 fail, 77 skipped (shared/realdata absent).
set -euo pipefail
case_name=$1 bench=$2 src=$3 out=$4
real=$src/../shared/realdata
py=/usr/bin/python3
rm -rf "$out" && mkdir -p "$out"
fail() { echo "FAIL [$case_name]: $*" >&2; exit 1; }

# The replay's outputs a person looks at.
expect_outputs() {
  for f in metrics.json report.html map.vdb map.ply costmap.pgm costmap.png; do
    [[ -s $1/$f ]] || fail "$1/$f missing"
  done
  grep -q "No ground truth" "$1/report.html" || fail "report.html does not say there is no ground truth"
  local frames
  frames=$(ls "$1"/frames/*_color.png | wc -l)
  [[ $frames -ge 1 ]] || fail "no depth frame pictures in $1/frames"
}

# metric PATH: a value of metrics.json.
metric() { $py -c "import json,sys; m=json.load(open(sys.argv[1])); print(eval('m' + sys.argv[2]))" "$1/metrics.json" "$2"; }

calc() { $py -c "print($1)"; }

# within VALUE LOWER UPPER WHAT
within() {
  $py -c "import sys; v,a,b=map(float,sys.argv[1:4]); sys.exit(0 if a<=v<=b else 1)" "$1" "$2" "$3" ||
    fail "$4 = $1, expected within [$2, $3]"
  echo "$4 = $1 within [$2, $3]"
}

case $case_name in
  d435)
    bag=$real/d435_office_corner/single_depth_color_640x480.bag
    [[ -f $bag ]] || { echo "SKIP: no $bag"; exit 77; }
    topic=/device_0/sensor_0/Depth_0/image/data
    info=$($py -c "
import rosbag, sys
with rosbag.Bag(sys.argv[1]) as b:
    for _, m, _ in b.read_messages(topics=[sys.argv[2]]):
        print(m.width, m.height, *m.K[0:6]); break" "$bag" /device_0/sensor_0/Depth_0/info/camera_info)
    read -r w h fx _ cx _ fy cy <<<"$info"
    stats=$($py "$src/tests/recording/depth_stats.py" "$bag" "$topic" 0.001)
    frames=$(grep -c '^frame' <<<"$stats")
    valid=$(awk -v n="$((w * h))" '/^frame/ {s += $5 / n; k++} END {printf "%.9f", s / k}' <<<"$stats")
    # A level camera 0.5 m above the floor, no decimation: every point in range and band marks its voxel.
    "$bench" replay "$bag" --out "$out/replay" --filter none --camera-pose 0,0,0.5,0,0,0 --no-progress
    expect_outputs "$out/replay"
    [[ $(metric "$out/replay" "['frames']") == "$frames" ]] || fail "frames $(metric "$out/replay" "['frames']") != $frames"
    [[ $(metric "$out/replay" "['recording']['width']") == "$w" ]] || fail "width"
    within "$(metric "$out/replay" "['recording']['fx']")" "$fx" "$fx" "fx"
    within "$(metric "$out/replay" "['recording']['fy']")" "$fy" "$fy" "fy"
    within "$(metric "$out/replay" "['recording']['cx']")" "$cx" "$cx" "cx"
    within "$(metric "$out/replay" "['recording']['cy']")" "$cy" "$cy" "cy"
    within "$(metric "$out/replay" "['valid_fraction_mean']")" "$(calc "$valid - 1e-9")" "$(calc "$valid + 1e-9")" "valid fraction"
    read -r lower upper < <($py "$src/tests/run/expected_replay_voxels.py" --bag "$bag" "$topic" 0.001 --pose 0,0,0.5 \
      --voxel 0.05 --range 3.0 --band 0.1 2.0 --fx "$fx" --fy "$fy" --cx "$cx" --cy "$cy")
    # 0.5 %: the bench projects in float32, the script in double; points within ~1e-6 m of a voxel face may differ.
    within "$(metric "$out/replay" "['map']['voxels']")" "$(calc "$lower * 0.995")" "$(calc "$upper * 1.005")" "map voxels"
    ;;

  kinect)
    dir=$real/robot_kinect_frames
    [[ -d $dir ]] || { echo "SKIP: no $dir"; exit 77; }
    # The frames' median depth is 3.4 to 3.9 m: mark up to 5 m so that most of them count.
    "$bench" replay "$dir" --out "$out/replay" --filter none --set map.observation.obstacle_range=5.0 --no-progress
    expect_outputs "$out/replay"
    [[ $(metric "$out/replay" "['frames']") == 2 ]] || fail "frames"
    [[ $(metric "$out/replay" "['recording']['pose_source']") == file ]] || fail "poses not from the calibration"
    within "$(metric "$out/replay" "['recording']['fx']")" 525 525 "fx"
    read -r lower upper < <($py "$src/tests/run/expected_replay_voxels.py" --png "$dir" --voxel 0.05 --range 5.0 --band 0.1 2.0)
    within "$(metric "$out/replay" "['map']['voxels']")" "$(calc "$lower * 0.995")" "$(calc "$upper * 1.005")" "map voxels"
    ;;

  roundtrip)
    scenario=$src/scenarios/office_corridor.yaml
    "$bench" run "$scenario" --duration 5 --out "$out/run" --bag "$out/run.bag" --no-progress >/dev/null || true
    [[ -s $out/run.bag ]] || fail "the run wrote no bag"
    "$bench" replay "$out/run.bag" --scenario "$scenario" --out "$out/replay" --bag "$out/replay.bag" --no-progress
    expect_outputs "$out/replay"
    [[ $(metric "$out/replay" "['recording']['pose_source']") == tf ]] || fail "poses not from /tf"
    [[ $(metric "$out/replay" "['frames']") == $(metric "$out/run" "['frames']") ]] || fail "frame counts differ"
    # The bag holds the noisy depth rounded to millimetres: voxels of points that moved across a voxel face
    # differ: agreement 0.99694 at 0.05 m when this test was written (1.00000 when the run itself rounds its depth
    # to mm); 0.99, the issue's bar, leaves 0.7 points.
    $py "$src/tests/scenarios/compare_ply_voxels.py" "$out/run/map.ply" "$out/replay/map.ply" 0.05 0.99 || fail "replayed map differs from the run's"
    # The replay's own bag: the same millimetre depth and poses (base_link -> camera in /tf_static); measured
    # 1.00000, required 0.999 (tf's doubles may move a point by an ulp across a voxel face).
    "$bench" replay "$out/replay.bag" --scenario "$scenario" --out "$out/replay2" --no-progress
    $py "$src/tests/scenarios/compare_ply_voxels.py" "$out/replay/map.ply" "$out/replay2/map.ply" 0.05 0.999 ||
      fail "the re-exported bag replays to another map"
    # The nav2 tutorial's STVL layer three ways: --params (the recording's camera bound by --camera-name), a
    # scenario that reads the parameter file, and that scenario's native twin: one map.
    if "$bench" replay "$out/run.bag" --params "$src/scenarios/ros/nav2_stvl_tutorial.yaml" --out "$out/unbound" \
        --no-progress 2>"$out/unbound.err"; then
      fail "a source bound to no camera was accepted"
    fi
    grep -q "add --camera-name intel_realsense_r200_depth" "$out/unbound.err" || fail "no --camera-name hint: $(cat "$out/unbound.err")"
    "$bench" replay "$out/run.bag" --params "$src/scenarios/ros/nav2_stvl_tutorial.yaml" \
      --camera-name intel_realsense_r200_depth --out "$out/params" --no-progress
    "$bench" replay "$out/run.bag" --scenario "$src/scenarios/nav2_stvl_tutorial.yaml" --out "$out/ros_scenario" --no-progress
    "$bench" replay "$out/run.bag" --scenario "$src/tests/scenarios/nav2_tutorial_native.yaml" --out "$out/native" --no-progress
    for other in ros_scenario native; do
      $py "$src/tests/scenarios/compare_ply_voxels.py" "$out/params/map.ply" "$out/$other/map.ply" 0.05 1.0 ||
        fail "--params and $other replay to different maps"
    done
    ;;
  *) echo "unknown case $case_name" >&2; exit 2 ;;
esac
# The bags are deleted once the checks pass (hundreds of MB each; CI disk); a failing run keeps them.
rm -f "$out"/*.bag
echo "PASS [$case_name]"
