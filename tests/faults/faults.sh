#!/usr/bin/env bash
# Fault tests for `stvl-bench run`: faults.sh CASE STVL_BENCH SOURCE_DIR. Exit 0 pass, 1 fail, 77 skipped.
# Each case runs in its own temporary directory and checks the exit code, the message and that nothing that
# looks like a finished result is left behind (metrics.json, report.html, map.vdb, a bag without .active).
set -uo pipefail
case_name=$1
bench=$2
src=$3
scenario=$src/scenarios/office_corridor.yaml
# Seconds allowed between a signal and the process exit (sanitizer builds are several times slower).
signal_limit_s=${STVL_FAULT_SIGNAL_LIMIT_S:-1.0}

tmp=$(mktemp -d "${TMPDIR:-/tmp}/stvl-fault.XXXXXX")
mounted=""
cleanup() {
  [[ -n "$mounted" ]] && umount "$mounted" 2>/dev/null
  rm -rf "$tmp"
}
trap cleanup EXIT

fail() {
  echo "FAIL [$case_name]: $*" >&2
  for f in "$tmp"/stdout "$tmp"/stderr; do [[ -s $f ]] && { echo "--- $(basename "$f"):" >&2; tail -n 20 "$f" >&2; }; done
  exit 1
}
skip() {
  echo "SKIP [$case_name]: $*"
  exit 77
}

# run_bench ARGS...: runs stvl-bench with stdout/stderr captured; sets $rc.
run_bench() {
  "$bench" "$@" >"$tmp/stdout" 2>"$tmp/stderr"
  rc=$?
}
expect_rc() {
  [[ $rc -eq $1 ]] || fail "exit code $rc, expected $1"
}
# The error is one line "stvl-bench: error: ..." on stderr that matches $1 (an ERE).
expect_error_line() {
  local line
  line=$(grep -E "^stvl-bench: error: " "$tmp/stderr" | head -n 1)
  [[ -n "$line" ]] || fail "no 'stvl-bench: error:' line on stderr"
  [[ "$line" =~ $1 ]] || fail "error line '$line' does not match /$1/"
  echo "message: $line"
}
# No file anywhere under $1 that looks like a complete result.
expect_no_results() {
  local found
  found=$(find "$1" \( -name metrics.json -o -name report.html -o -name junit.xml -o -name map.vdb -o -name '*.bag' \) -print 2>/dev/null)
  [[ -z "$found" ]] || fail "left files that look complete: $found"
}

case $case_name in
  out_under_file)
    # --out names a path below a regular file: nothing can be created there.
    touch "$tmp/plain_file"
    run_bench run "$scenario" --out "$tmp/plain_file/out" --no-progress --duration 1
    expect_rc 2
    expect_error_line "plain_file/out"
    expect_no_results "$tmp"
    ;;

  bag_under_file)
    # The output directory is fine but the bag cannot be created.
    touch "$tmp/plain_file"
    run_bench run "$scenario" --out "$tmp/out" --bag "$tmp/plain_file/run.bag" --no-progress --duration 1
    expect_rc 2
    expect_error_line "plain_file/run.bag"
    expect_no_results "$tmp"
    ;;

  bag_replaces_out | replay_bag_replaces_out)
    # --bag taking the place of --out or of a folder above it (a rosbag2 folder is named after the .mcap's stem):
    # the outputs would replace the bag (before, a run lost it and exited 0). Exit 2 before anything is written,
    # naming both paths. A bag inside --out stays allowed (a run moves it with its outputs).
    cmd=(run "$scenario" --duration 0.5)
    if [[ $case_name == replay_* ]]; then
      "$bench" run "$scenario" --duration 0.5 --out "$tmp/rec/run" --bag "$tmp/rec/src.bag" --no-progress >/dev/null 2>&1 ||
        fail "could not write the recording to replay"
      cmd=(replay "$tmp/rec/src.bag")
    fi
    t=$tmp/t
    mkdir -p "$t/x"
    for args in "$t/same --bag $t/same.mcap" "$t/bag/out --bag $t/bag.mcap" "$t/ros2 --bag $t/ros2 --bag-format ros2" \
      "$t/ros1 --bag $t/ros1" "$t/x/../dots --bag $t/dots.mcap"; do
      # shellcheck disable=SC2086  # each case is split into its arguments on purpose
      run_bench "${cmd[@]}" --no-progress --out $args
      expect_rc 2
      read -r out _ bag _ <<<"$args"
      expect_error_line "--bag ${bag//./[.]} writes .* which (is|holds) the output folder --out ${out//./[.]}:"
      [[ -e ${out%/out} || -e ${out%/out}.active || -e $bag ]] && fail "left ${out%/out} or its bag"
    done
    expect_no_results "$t"
    ;;

  file_size_limit)
    # Disk full, simulated with RLIMIT_FSIZE (writes past 4 MiB fail with EFBIG; SIGXFSZ ignored so that the
    # write fails instead of killing the process). The bag outgrows it within the first frames.
    (
      trap '' XFSZ
      ulimit -f 4096
      exec "$bench" run "$scenario" --out "$tmp/out" --bag "$tmp/out/run.bag" --no-progress --duration 3
    ) >"$tmp/stdout" 2>"$tmp/stderr"
    rc=$?
    expect_rc 2
    expect_error_line "run\.bag"
    expect_no_results "$tmp"
    ;;

  file_size_limit_outputs)
    # Same without a bag: the first output that outgrows 64 KiB (a depth PNG or map.vdb) must fail the run.
    (
      trap '' XFSZ
      ulimit -f 64
      exec "$bench" run "$scenario" --out "$tmp/out" --no-progress --duration 2
    ) >"$tmp/stdout" 2>"$tmp/stderr"
    rc=$?
    expect_rc 2
    expect_error_line "$tmp/out"
    [[ -e "$tmp/out/metrics.json" ]] && fail "metrics.json written although an output failed"
    [[ -n "$(find "$tmp" -name '*.tmp')" ]] && fail "temporary files left: $(find "$tmp" -name '*.tmp')"
    ;;

  tmpfs_full)
    # A real full file system: a 6 MiB tmpfs (needs root and a mount namespace that allows it; skipped otherwise).
    mkdir -p "$tmp/mnt"
    mount -t tmpfs -o size=6m stvl-fault "$tmp/mnt" 2>/dev/null || skip "cannot mount a tmpfs here"
    mounted=$tmp/mnt
    run_bench run "$scenario" --out "$tmp/mnt/out" --bag "$tmp/mnt/out/run.bag" --no-progress --duration 3
    expect_rc 2
    expect_error_line "run\.bag"
    expect_no_results "$tmp/mnt"
    ;;

  sigint | sigterm)
    signal=${case_name#sig}
    signal=${signal^^}
    "$bench" run "$scenario" --out "$tmp/out" --bag "$tmp/out/run.bag" --no-progress >"$tmp/stdout" 2>"$tmp/stderr" &
    pid=$!
    # About 3 s in, and at least until the frame loop has started (the bag exists).
    sleep 3
    for _ in $(seq 1 200); do
      # The run writes into a staging folder beside --out (common/staged_directory.hpp), the bag with it.
      compgen -G "$tmp/out.partial-*/run.bag.active" >/dev/null && break
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.1
    done
    kill -0 "$pid" 2>/dev/null || { wait "$pid"; rc=$?; fail "exited (code $rc) before the signal"; }
    sent=$(date +%s.%N)
    kill -s "$signal" "$pid"
    rc=""
    for _ in $(seq 1 600); do
      if ! kill -0 "$pid" 2>/dev/null; then break; fi
      sleep 0.02
    done
    exited=$(date +%s.%N)
    if kill -0 "$pid" 2>/dev/null; then
      kill -s KILL "$pid"
      wait "$pid"
      fail "still running 12 s after SIG$signal"
    fi
    wait "$pid"
    rc=$?
    took=$(awk -v a="$sent" -v b="$exited" 'BEGIN { printf "%.2f", b - a }')
    echo "exited ${took}s after SIG$signal with code $rc"
    awk -v t="$took" -v l="$signal_limit_s" 'BEGIN { exit !(t <= l) }' || fail "took ${took}s to exit, limit ${signal_limit_s}s"
    expected=$((128 + $(kill -l "$signal")))
    expect_rc "$expected"
    grep -q "interrupted by signal" "$tmp/stderr" || fail "no 'interrupted by signal' message"
    expect_no_results "$tmp"
    [[ -e "$tmp/out" ]] && fail "an interrupted run created $tmp/out"
    grep -q "interrupted by signal" "$tmp/out.incomplete/INCOMPLETE" || fail "the partial output is not marked INCOMPLETE"
    [[ -e "$tmp/out.incomplete/run.bag.active" ]] || fail "the bag did not stay as run.bag.active in out.incomplete"
    ;;

  rerun_same_out)
    # Issue 31: a second run into the same --out kept the first one's frames/*.png, and an interrupted run into
    # an old folder left the old complete results mixed with its own. Now a completed run replaces the folder
    # whole; an interrupted one leaves it untouched and its own output in out.incomplete, marked.
    run_bench run "$scenario" --out "$tmp/out" --no-progress --duration 1
    expect_rc 0
    touch "$tmp/out/frames/depth_99999_color.png"
    run_bench run "$scenario" --out "$tmp/out" --no-progress --duration 1
    expect_rc 0
    [[ -e "$tmp/out/frames/depth_99999_color.png" ]] && fail "the second run kept the first run's frame"
    [[ -n "$(compgen -G "$tmp/out.*")" ]] && fail "left beside the folder: $(compgen -G "$tmp/out.*")"
    before=$(md5sum "$tmp/out/metrics.json")
    "$bench" run "$scenario" --out "$tmp/out" --no-progress >"$tmp/stdout" 2>"$tmp/stderr" &
    pid=$!
    for _ in $(seq 1 1200); do  # up to 120 s (ASan on a busy machine): the interrupt must come after a frame
      compgen -G "$tmp/out.partial-*/frames/*.png" >/dev/null && break
      sleep 0.1
    done
    compgen -G "$tmp/out.partial-*/frames/*.png" >/dev/null || fail "no frame written within 120 s"
    kill -s INT "$pid"
    wait "$pid"
    rc=$?
    expect_rc 130
    [[ "$(md5sum "$tmp/out/metrics.json")" == "$before" ]] || fail "the interrupted run changed the old results"
    grep -q "interrupted by signal 2" "$tmp/out.incomplete/INCOMPLETE" || fail "the partial output is not marked"
    [[ -e "$tmp/out.incomplete/metrics.json" ]] && fail "the partial output holds a metrics.json"
    echo "a completed run replaced the folder whole; the interrupted one left it as it was"
    ;;

  waypoint_into_wall)
    # Issue 31: a waypoint into a wall failed only path_completed, with no word that the robot was blocked, or where.
    run_bench run "$scenario" --set 'robot.waypoints=[[0, 0], [0, 4]]' --set duration_s=8 --out "$tmp/out" --no-progress
    expect_rc 1
    grep -Eq "^FAIL path_completed +did not reach the end of the path within 8.0 s: blocked at \(0.00, 0.[0-9]+\) m since t = [0-9.]+ s, [0-9.]+ m short of the path's end, touching walls$" "$tmp/stdout" ||
      fail "no blocked diagnosis on the path_completed line"
    grep -E "path_completed" "$tmp/stdout"
    ;;

  twin_drive_key)
    # A twin shares its run's drive: a key that changes what is simulated, rendered or made noisy is refused.
    run_bench run "$scenario" --out "$tmp/out" --twin "$tmp/twin;map.voxel_size=0.1;seed=3" --no-progress --duration 1
    expect_rc 2
    expect_error_line "--twin .*'seed' may change the drive"
    expect_no_results "$tmp"
    run_bench sweep "$scenario" --set map.voxel_size=0.05,0.1 --out "$tmp/sweep" --twin "$tmp/sweep_twin;camera.noise.enabled=false"
    expect_rc 2
    expect_error_line "'camera.noise.enabled' may change the drive"
    expect_no_results "$tmp"
    ;;

  twin_same_out)
    run_bench run "$scenario" --out "$tmp/out" --twin "$tmp/out/../out;map.voxel_size=0.1" --no-progress --duration 1
    expect_rc 2
    expect_error_line "two runs would write"
    expect_no_results "$tmp"
    # A twin inside the run's folder would go with it when the run's outputs replace the folder.
    run_bench run "$scenario" --out "$tmp/out" --twin "$tmp/out/twin;map.voxel_size=0.1" --no-progress --duration 1
    expect_rc 2
    expect_error_line "two runs would write .*neither inside the other"
    expect_no_results "$tmp"
    run_bench sweep "$scenario" --set map.voxel_size=0.05,0.1 --out "$tmp/sweep" --twin "$tmp/sweep/inner;map.voxel_size=0.1"
    expect_rc 2
    expect_error_line "must lie apart from the sweep's folder"
    ;;

  twin_same_as_alone)
    # The command line's twin: its outputs are those of its own run, and so are its run's.
    fixes=(map.clearing_mode=raycast camera.edge_filter.enabled=true map.mark_rounding=floor)
    run_bench run "$scenario" --out "$tmp/a" --twin "$tmp/b;$(IFS=';'; echo "${fixes[*]}")" --no-progress --duration 3
    expect_rc 0
    sets=()
    for s in "${fixes[@]}"; do sets+=(--set "$s"); done
    run_bench run "$scenario" --out "$tmp/b_alone" "${sets[@]}" --no-progress --duration 3
    expect_rc 0
    run_bench run "$scenario" --out "$tmp/a_alone" --no-progress --duration 3
    expect_rc 0
    for f in map.ply costmap.pgm; do
      cmp "$tmp/a/$f" "$tmp/a_alone/$f" || fail "the run's $f differs from its run alone"
      cmp "$tmp/b/$f" "$tmp/b_alone/$f" || fail "the twin's $f differs from its run alone"
    done
    cmp -s "$tmp/a/map.ply" "$tmp/b/map.ply" && fail "the two behaviours gave the same map: the check above proves nothing"
    [[ -f "$tmp/b/metrics.json" && -f "$tmp/b/report.html" ]] || fail "the twin has no metrics.json or report.html"
    ;;

  gl_bogus)
    STVL_GL=bogus run_bench run "$scenario" --out "$tmp/out" --no-progress --duration 1
    expect_rc 2
    expect_error_line "bogus"
    [[ $(grep -c . "$tmp/stderr") -le 2 ]] || fail "more than a short message on stderr"
    expect_no_results "$tmp"
    ;;

  gl_missing)
    # libEGL and libOSMesa are dlopen'ed by soname: empty files with those names first on LD_LIBRARY_PATH make
    # both fail to load, as on a machine without them.
    mkdir -p "$tmp/nogl"
    for lib in libEGL.so.1 libEGL.so libOSMesa.so.8 libOSMesa.so.6 libOSMesa.so; do : >"$tmp/nogl/$lib"; done
    LD_LIBRARY_PATH="$tmp/nogl${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" run_bench run "$scenario" --out "$tmp/out" --no-progress --duration 1
    expect_rc 2
    expect_error_line "OpenGL|EGL|OSMesa"
    expect_no_results "$tmp"
    ;;

  gl_missing_osmesa)
    # Only OSMesa asked for, and it is missing.
    mkdir -p "$tmp/nogl"
    for lib in libOSMesa.so.8 libOSMesa.so.6 libOSMesa.so; do : >"$tmp/nogl/$lib"; done
    STVL_GL=osmesa LD_LIBRARY_PATH="$tmp/nogl${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}" \
      run_bench run "$scenario" --out "$tmp/out" --no-progress --duration 1
    expect_rc 2
    expect_error_line "OSMesa"
    expect_no_results "$tmp"
    ;;

  robot_falls)
    # A 2 m platform 3 m above a wide floor: the path leads off its edge and the robot falls. (The lower floor
    # keeps the waypoints inside the world's extent, which a run checks before driving.)
    cp "$src/worlds/robot.xml" "$tmp/"
    cat >"$tmp/platform.xml" <<'EOF'
<mujoco model="platform">
  <compiler autolimits="true" angle="radian"/>
  <option timestep="0.002"/>
  <statistic extent="1" center="0 0 0"/>
  <visual>
    <quality offsamples="0" shadowsize="0"/>
    <global offwidth="1280" offheight="960"/>
    <map znear="0.01" zfar="50"/>
  </visual>
  <include file="robot.xml"/>
  <worldbody>
    <light name="sun" directional="true" pos="0 0 10" dir="0 0 -1" castshadow="false"/>
    <geom name="floor" type="box" pos="0 0 -0.05" size="1 1 0.05" group="0"/>
    <geom name="ground" type="plane" pos="0 0 -3" size="8 8 0.1" group="0"/>
    <body name="box_1" pos="0.8 0.6 0.2">
      <geom type="box" size="0.1 0.1 0.2" group="1"/>
    </body>
  </worldbody>
</mujoco>
EOF
    cat >"$tmp/falls.yaml" <<'EOF'
name: robot_falls
world: platform.xml
duration_s: 12
robot:
  start: [0.0, 0.0, 0.0]
  waypoints: [[0.0, 0.0], [6.0, 0.0]]
  speed_mps: 0.8
camera: {preset: d435_640x480, rate_hz: 10, noise: {enabled: false}}
EOF
    run_bench run "$tmp/falls.yaml" --out "$tmp/out" --no-progress
    expect_rc 1
    grep -Eq "^FAIL robot_upright +the robot fell over or left the world" "$tmp/stdout" ||
      fail "no 'FAIL robot_upright ... fell over or left the world' line on stdout"
    grep -E "robot_upright" "$tmp/stdout"
    ;;

  world_missing)
    sed "s#^world: .*#world: does_not_exist.xml#" "$scenario" >"$tmp/missing.yaml"
    run_bench run "$tmp/missing.yaml" --out "$tmp/out" --no-progress
    expect_rc 2
    expect_error_line "does_not_exist\.xml"
    expect_no_results "$tmp"
    ;;

  mesh_missing | mesh_absurd_size | mesh_not_finite)
    # The mesh_room world with a mesh file that is not there (MuJoCo's error, naming the file), a scan read in the
    # wrong units (x 1e5: refused before its voxels are allocated, naming the geom), a vertex beyond float range.
    mkdir -p "$tmp/meshes"
    cp "$src/worlds/robot.xml" "$tmp/"
    cp "$src"/worlds/meshes/*.obj "$src"/worlds/meshes/*.stl "$tmp/meshes/"
    sed "s#^world: .*#world: world.xml#" "$src/scenarios/mesh_room.yaml" >"$tmp/scan.yaml"
    case $case_name in
      mesh_missing) sed 's#file="mesh_room.obj"#file="no_such_scan.obj"#' "$src/worlds/mesh_room.xml" >"$tmp/world.xml" ;;
      mesh_absurd_size) sed 's#file="mesh_room.obj"#file="mesh_room.obj" scale="1e5 1e5 1e5"#' "$src/worlds/mesh_room.xml" >"$tmp/world.xml" ;;
      mesh_not_finite)
        sed '0,/^v .*/s//v 1e39 0 0/' "$src/worlds/meshes/mesh_room.obj" >"$tmp/meshes/mesh_room.obj"
        cp "$src/worlds/mesh_room.xml" "$tmp/world.xml" ;;
    esac
    start=$(date +%s)
    run_bench run "$tmp/scan.yaml" --out "$tmp/out" --no-progress
    expect_rc 2
    case $case_name in
      mesh_missing) expect_error_line "no_such_scan\.obj" ;;
      mesh_absurd_size)
        expect_error_line "geom 'room_scan' .*candidate voxels"
        (( $(date +%s) - start < 30 )) || fail "took $(( $(date +%s) - start )) s to refuse" ;;
      mesh_not_finite) expect_error_line "geom 'room_scan' .*vertex 0 is not finite" ;;
    esac
    expect_no_results "$tmp"
    ;;

  scenario_malformed)
    printf 'name: x\nworld: [unclosed\n' >"$tmp/bad.yaml"
    run_bench run "$tmp/bad.yaml" --out "$tmp/out" --no-progress
    expect_rc 2
    expect_error_line "bad\.yaml:[0-9]+"
    expect_no_results "$tmp"
    ;;

  ros_params_malformed | ros_layer_missing | ros_plugin_not_stvl | ros_source_unbound)
    # The nav2 tutorial scenario with its parameter file edited: each edit exits 2 naming file, line and key.
    params=$src/scenarios/ros/nav2_stvl_tutorial.yaml
    layer=stvl_layer pattern=""
    case $case_name in
      ros_params_malformed) sed 's#^        voxel_size: 0.05#        voxel_size: [0.05#' "$params" >"$tmp/p.yaml"
                            pattern="p\.yaml:[0-9]+: YAML syntax error" ;;
      ros_layer_missing) cp "$params" "$tmp/p.yaml"; layer=stvl
                         pattern="p\.yaml:[0-9]+: .*stvl.*(stvl_layer)" ;;
      ros_plugin_not_stvl) sed 's#spatio_temporal_voxel_layer/SpatioTemporalVoxelLayer#my_pkg::MyLayer#' \
                             "$params" >"$tmp/p.yaml"
                           pattern="p\.yaml:24: stvl_layer\.plugin: plugin is 'my_pkg::MyLayer', not .*VoxelLayer" ;;
      ros_source_unbound) sed 's#topic: /intel_realsense_r200_depth/points#topic: /other_camera/points#' \
                            "$params" >"$tmp/p.yaml"
                          pattern="p\.yaml:42: stvl_layer\.pointcloud: bound to no camera" ;;
    esac
    sed -e "s#^world: .*#world: $src/worlds/office_corridor.xml#" -e "s#ros_params: .*#ros_params: $tmp/p.yaml#" \
      -e "s#layer: stvl_layer#layer: $layer#" "$src/scenarios/nav2_stvl_tutorial.yaml" >"$tmp/s.yaml"
    run_bench run "$tmp/s.yaml" --out "$tmp/out" --no-progress --duration 1
    expect_rc 2
    expect_error_line "$pattern"
    expect_no_results "$tmp"
    ;;

  nav2_laserscan | nav2_z_voxels | nav2_range_nan | nav2_source_unbound)
    # nav2's VoxelLayer file of scenarios/nav2_voxel_layer.yaml edited: each edit exits 2 naming file, line and key.
    params=$src/scenarios/ros/nav2_voxel_layer.yaml
    case $case_name in
      nav2_laserscan) sed 's#data_type: "PointCloud2"#data_type: "LaserScan"#' "$params" >"$tmp/p.yaml"
                      pattern="p\.yaml:35: voxel_layer\.pointcloud\.data_type: LaserScan is not simulated" ;;
      nav2_z_voxels) sed 's#z_voxels: 16#z_voxels: 17#' "$params" >"$tmp/p.yaml"
                     pattern="p\.yaml:29: voxel_layer\.z_voxels: 17: must lie in \[1, 16\]" ;;
      nav2_range_nan) sed 's#raytrace_max_range: 3.0#raytrace_max_range: .nan#' "$params" >"$tmp/p.yaml"
                      pattern="p\.yaml:40: voxel_layer\.pointcloud\.raytrace_max_range: nan: must be finite" ;;
      nav2_source_unbound) sed 's#topic: /camera/depth/points#topic: /other_camera/points#' "$params" >"$tmp/p.yaml"
                           pattern="p\.yaml:[0-9]+: voxel_layer\.pointcloud: bound to no camera" ;;
    esac
    sed -e "s#^world: .*#world: $src/worlds/office_corridor.xml#" -e "s#ros_params: .*#ros_params: $tmp/p.yaml#" \
      "$src/scenarios/nav2_voxel_layer.yaml" >"$tmp/s.yaml"
    run_bench run "$tmp/s.yaml" --out "$tmp/out" --no-progress --duration 1
    expect_rc 2
    expect_error_line "$pattern"
    expect_no_results "$tmp"
    ;;

  cameras_same_name | camera_inside_body | camera_below_floor)
    three=$src/scenarios/delivery_robot_3cams.yaml
    case $case_name in
      cameras_same_name) sed 's#name: left_camera#name: front_camera#' "$three" >"$tmp/s.yaml"
                         pattern="s\.yaml:[0-9]+: robot\.cameras\[1\]\.name: two cameras are named 'front_camera'" ;;
      camera_inside_body) sed 's#xyz_m: \[0.15, 0.0, 0.5\]#xyz_m: [0.1, 0.0, 0.2]#' "$three" >"$tmp/s.yaml"
                          pattern="s\.yaml:15: robot\.cameras\[0\]\.mount: camera 'front_camera': mounted inside the robot's body \(geom 'base_shell'\)" ;;
      camera_below_floor) sed 's#xyz_m: \[0.15, 0.0, 0.5\]#xyz_m: [0.15, 0.0, -0.2]#' "$three" >"$tmp/s.yaml"
                          pattern="s\.yaml:[0-9]+: robot\.cameras\[0\]\.mount\.xyz_m: z must be > 0 m" ;;
    esac
    sed -i "s#^world: .*#world: $src/worlds/office_corridor.xml#" "$tmp/s.yaml"
    run_bench run "$tmp/s.yaml" --out "$tmp/out" --no-progress --duration 1
    expect_rc 2
    expect_error_line "$pattern"
    expect_no_results "$tmp"
    ;;

  self_radius_negative | self_radius_inf | self_footprint_short | self_footprint_nan | self_geom_unknown | \
  self_check_no_footprint | self_ros_radius_negative)
    # The robot seeing itself: a bad footprint, robot radius or seen geom names its file, line and key.
    self=$src/scenarios/robot_sees_itself.yaml
    case $case_name in
      self_radius_negative) sed 's#  footprint: .*#  robot_radius: -0.1#' "$self" >"$tmp/s.yaml"
                            pattern="s\.yaml:[0-9]+: map\.robot_radius: must be finite and > 0 m" ;;
      self_radius_inf) sed 's#  footprint: .*#  robot_radius: .inf#' "$self" >"$tmp/s.yaml"
                       pattern="s\.yaml:[0-9]+: map\.robot_radius: must be finite and > 0 m" ;;
      self_footprint_short) sed 's#  footprint: .*#  footprint: [[0.3, 0.2], [0.3, -0.2]]#' "$self" >"$tmp/s.yaml"
                            pattern="s\.yaml:[0-9]+: map\.footprint: needs at least three" ;;
      self_footprint_nan) sed 's#  footprint: .*#  footprint: [[0.3, .nan], [0.3, -0.2], [-0.2, 0.0]]#' "$self" >"$tmp/s.yaml"
                          pattern="s\.yaml:[0-9]+: map\.footprint: points must be finite" ;;
      self_geom_unknown) sed 's#geoms_seen_by_cameras: .*#geoms_seen_by_cameras: [no_such_geom]#' "$self" >"$tmp/s.yaml"
                         pattern="s\.yaml:[0-9]+: robot\.geoms_seen_by_cameras: no geom named 'no_such_geom'" ;;
      self_check_no_footprint) sed 's#  footprint: .*##' "$self" >"$tmp/s.yaml"
                               pattern="s\.yaml:[0-9]+: checks\.self_lethal_cells_max: needs the robot's footprint" ;;
      self_ros_radius_negative)
        sed 's#robot_radius: 0.22#robot_radius: -0.22#' "$src/scenarios/ros/nav2_stvl_tutorial.yaml" >"$tmp/p.yaml"
        sed "s#ros_params: .*#ros_params: $tmp/p.yaml#" "$src/scenarios/nav2_stvl_tutorial.yaml" >"$tmp/s.yaml"
        pattern="p\.yaml:[0-9]+: local_costmap\.robot_radius: must be finite and > 0 m" ;;
    esac
    sed -i "s#^world: .*#world: $src/worlds/office_corridor.xml#" "$tmp/s.yaml"
    run_bench run "$tmp/s.yaml" --out "$tmp/out" --no-progress --duration 1
    expect_rc 2
    expect_error_line "$pattern"
    expect_no_results "$tmp"
    ;;
  edge_filter_bad_threshold)
    # A negative and a non-finite jump threshold of the edge filter: exit 2 naming file, line and key.
    for value in -0.03 .nan .inf; do
      sed "s#^  noise: {enabled: true}#&\n  edge_filter: {enabled: true, max_jump_at_1m_m: $value}#" "$scenario" >"$tmp/s.yaml"
      sed -i "s#^world: .*#world: $src/worlds/office_corridor.xml#" "$tmp/s.yaml"
      run_bench run "$tmp/s.yaml" --out "$tmp/out" --no-progress --duration 1
      expect_rc 2
      expect_error_line "s\.yaml:16: camera\.edge_filter\.max_jump_at_1m_m: .*must be finite and > 0 m"
      expect_no_results "$tmp"
    done
    ;;

  outage_reversed | outage_past_end | outage_overlap | outage_not_finite)
    # camera_outage.yaml with its front camera's outages edited: each exits 2 naming file, line and key.
    sc=$src/scenarios/camera_outage.yaml
    key="s\.yaml:22: robot\.cameras\[0\]\.outages"
    case $case_name in
      outage_reversed) edit='[{from_s: 8.0, to_s: 5.0}]' pattern="$key\[0\]\.to_s: must be finite and > from_s" ;;
      outage_past_end) edit='[{from_s: 5.0, to_s: 20.0}]' pattern="$key\[0\]\.to_s: must be <= duration_s" ;;
      outage_overlap) edit='[{from_s: 5.0, to_s: 8.0}, {from_s: 7.0, to_s: 9.0}]'
                      pattern="$key\[1\]\.from_s: overlaps outages\[0\]" ;;
      outage_not_finite) edit='[{from_s: .nan, to_s: 8.0}]' pattern="$key\[0\]\.from_s: must be finite" ;;
    esac
    sed -e "s#^world: .*#world: $src/worlds/office_corridor.xml#" -e "s#outages: \[.*\]#outages: $edit#" "$sc" >"$tmp/s.yaml"
    grep -qF "outages: $edit" "$tmp/s.yaml" || fail "the edit did not apply"
    run_bench run "$tmp/s.yaml" --out "$tmp/out" --no-progress --duration 1
    expect_rc 2
    expect_error_line "$pattern"
    expect_no_results "$tmp"
    ;;

  buffer_rate_negative | buffer_persistence_not_finite | drop_without_rate)
    # camera_outage.yaml's STVL buffer keys edited (map.observation): each exits 2 naming file, line and key.
    sc=$src/scenarios/camera_outage.yaml
    case $case_name in
      buffer_rate_negative) from='expected_update_rate: 0.5' to='expected_update_rate: -0.5'
                            pattern="s\.yaml:[0-9]+: map\.observation\.expected_update_rate: .*must be >= 0 s" ;;
      buffer_persistence_not_finite) from='observation_persistence: 0.0' to='observation_persistence: .inf'
                                     pattern="s\.yaml:[0-9]+: map\.observation\.observation_persistence: .*finite" ;;
      drop_without_rate) from='expected_update_rate: 0.5' to='expected_update_rate: 0.0\n    drop_when_not_current: true'
                         pattern="s\.yaml:[0-9]+: map\.observation\.drop_when_not_current: needs expected_update_rate > 0 s" ;;
    esac
    sed -e "s#^world: .*#world: $src/worlds/office_corridor.xml#" -e "s#$from#$to#" "$sc" >"$tmp/s.yaml"
    grep -qF "${to%%\\n*}" "$tmp/s.yaml" || fail "the edit did not apply"
    run_bench run "$tmp/s.yaml" --out "$tmp/out" --no-progress --duration 1
    expect_rc 2
    expect_error_line "$pattern"
    expect_no_results "$tmp"
    ;;

  soak_loop_one_waypoint | soak_repeat_too_short | soak_loop_stops_at_end | soak_check_without_samples)
    # The soak patrol (issue #270) edited: each edit exits 2 naming file, line and key.
    soak=$src/tests/scenarios/soak_patrol.yaml
    case $case_name in
      soak_loop_one_waypoint) sed 's#waypoints: \[\[0.0, 0.0\], \[21.0, 0.0\]\]#waypoints: [[0.0, 0.0]]#' "$soak" >"$tmp/s.yaml"
                              pattern="s\.yaml:14: robot\.waypoints: a looping path needs at least 2 distinct waypoints, got 1" ;;
      soak_repeat_too_short) sed 's#repeat_s: 45#repeat_s: 12#' "$soak" >"$tmp/s.yaml"
                             pattern="s\.yaml:23: moving_bodies\[0\]\.repeat_s: must be finite, > 0 and at least the keyframes' span 18 s, got 12" ;;
      soak_loop_stops_at_end) sed 's#^duration_s: 1800#duration_s: 1800\nstop_at_path_end: true#' "$soak" >"$tmp/s.yaml"
                              pattern="s\.yaml:12: stop_at_path_end: robot\.loop never reaches an end" ;;
      soak_check_without_samples) sed 's#soak_sample_every_s: 60#soak_sample_every_s: 0#' "$soak" >"$tmp/s.yaml"
                                  pattern="s\.yaml:[0-9]+: checks\.soak_rss_growth_max: needs evaluation\.soak_sample_every_s > 0" ;;
    esac
    sed -i "s#^world: .*#world: $src/worlds/office_corridor.xml#" "$tmp/s.yaml"
    run_bench run "$tmp/s.yaml" --out "$tmp/out" --no-progress --duration 1
    expect_rc 2
    expect_error_line "$pattern"
    expect_no_results "$tmp"
    ;;

  lint_exit_codes)
    # 1 with findings (the tutorial file), 0 clean, 2 unreadable.
    run_bench lint "$src/scenarios/ros/nav2_stvl_tutorial.yaml"
    expect_rc 1
    grep -q "nav2_stvl_tutorial.yaml:52: stvl_layer.pointcloud.voxel_filter: " "$tmp/stdout" || fail "no voxel_filter finding"
    printf 'observation_sources: cam\nvoxel_size: 0.05\nvoxel_decay: 15.0\ncam:\n  topic: /cam/points\n  clearing: true\n  min_obstacle_height: 0.1\n  max_z: 4.0\n  obstacle_range: 3.0\n  decay_acceleration: 5.0\n' >"$tmp/clean.yaml"
    run_bench lint "$tmp/clean.yaml"
    expect_rc 0
    printf 'observation_sources: [\n' >"$tmp/broken.yaml"
    run_bench lint "$tmp/broken.yaml"
    expect_rc 2
    expect_error_line "broken\.yaml:[0-9]+"
    ;;

  hidden_false_clears_negative)
    # A negative bound of the occlusion check names its line in the scenario file.
    sed -e "s#^world: .*#world: $src/worlds/cart_crossing.xml#" \
      -e "s#^  hidden_false_clears_max: .*#  hidden_false_clears_max: -1#" "$src/scenarios/cart_crossing.yaml" >"$tmp/s.yaml"
    line=$(grep -n "^  hidden_false_clears_max: -1" "$tmp/s.yaml" | cut -d: -f1)
    [[ -n "$line" ]] || fail "no hidden_false_clears_max line in cart_crossing.yaml"
    run_bench run "$tmp/s.yaml" --out "$tmp/out" --no-progress --duration 1
    expect_rc 2
    expect_error_line "s\.yaml:$line: checks\.hidden_false_clears_max: .*must be >= 0"
    expect_no_results "$tmp"
    ;;

  replay_bag_truncated | replay_bag_no_depth | replay_bag_rgb8 | replay_bag_mono8 | replay_bag_size_mismatch | \
  replay_bag_short_step | replay_bag_zero_fx | replay_bag_nan_fx)
    # A malformed recording, written by this test (make_bad_recording.py with ROS 1's message definitions, no
    # real recording needed): exit 2 with a message naming the fault, nothing left that looks complete.
    kind=${case_name#replay_bag_}
    /usr/bin/python3 "$src/tests/faults/make_bad_recording.py" "$kind" - "$tmp/bad.bag" || fail "could not write the bad bag"
    run_bench replay "$tmp/bad.bag" --out "$tmp/out" --no-progress
    expect_rc 2
    case $kind in
      truncated) expect_error_line "bad\.bag: cannot read the bag \(truncated or corrupt" ;;
      no_depth) expect_error_line "bad\.bag: no depth topic .*the bag has: /camera/depth/camera_info.*--depth-topic" ;;
      rgb8) expect_error_line "image_rect_raw: encoding 'rgb8' is not depth" ;;
      mono8) expect_error_line "image_rect_raw: encoding '8UC1' is not depth" ;;
      size_mismatch) expect_error_line "frame 0: image is 64x48 but /camera/depth/camera_info says 128x96" ;;
      short_step) expect_error_line "frame 0: step 64 < width x 2 bytes = 128" ;;
      zero_fx) expect_error_line "camera_info K: bad intrinsics: fx = 0" ;;
      nan_fx) expect_error_line "camera_info K: bad intrinsics: fx = nan" ;;
    esac
    expect_no_results "$tmp/out"
    ;;

  replay_png_empty | replay_png_mixed | replay_png_sizes | replay_png_pose_not_rigid | replay_png_no_intrinsics | \
  replay_missing)
    # A malformed PNG folder (built here from the real Kinect frames) or a recording that does not exist.
    real=$src/../shared/realdata/robot_kinect_frames
    [[ -d $real ]] || skip "no $real (shared/realdata beside the checkout)"
    mkdir -p "$tmp/rec/depth"
    printf 'width: 640\nheight: 480\nfx: 525\nfy: 525\ncx: 319.5\ncy: 239.5\n' >"$tmp/rec/intrinsics.yaml"
    cp "$real/depth/17.png" "$tmp/rec/depth/1.png"
    cp "$real/depth/154.png" "$tmp/rec/depth/2.png"
    case $case_name in
      replay_png_empty) rm "$tmp/rec/depth/"*.png ;;
      replay_png_mixed) echo "not a png" >"$tmp/rec/depth/3.txt" ;;
      replay_png_sizes) cp "$src/tests/faults/rgb_4x4.png" "$tmp/rec/depth/3.png" ;;  # an 8-bit colour PNG
      replay_png_pose_not_rigid) printf '0 0 0 0 0 0 0 1\n0.033 0 0 0 0 0 0 2\n' >"$tmp/rec/poses.txt" ;;
      replay_png_no_intrinsics) rm "$tmp/rec/intrinsics.yaml" ;;
      replay_missing) rm -rf "$tmp/rec" ;;
    esac
    run_bench replay "$tmp/rec" --out "$tmp/out" --no-progress
    expect_rc 2
    case $case_name in
      replay_png_empty) expect_error_line "rec.*(no|empty).*PNG|rec.*PNG.*(none|empty)" ;;
      replay_png_mixed) expect_error_line "3\.txt" ;;
      replay_png_sizes) expect_error_line "3\.png" ;;
      replay_png_pose_not_rigid) expect_error_line "poses\.txt:2.*(quaternion|rigid)" ;;
      replay_png_no_intrinsics) expect_error_line "rec.*intrinsics" ;;
      replay_missing) expect_error_line "rec.*(does not exist|no such|not found)" ;;
    esac
    expect_no_results "$tmp"
    ;;

  noise_stats_missing | noise_stats_one_frame | noise_stats_not_a_recording)
    # stvl-bench noise-stats needs a readable recording with two frames of a static camera: else exit 2.
    case $case_name in
      noise_stats_missing) real=$tmp/none.bag pattern="none\.bag" ;;
      noise_stats_one_frame)  # the first Kinect frame alone, with its calibration
        mkdir -p "$tmp/one/depth" "$tmp/one/calib"
        cp "$src/../shared/realdata/robot_kinect_frames/depth/17.png" "$tmp/one/depth/" 2>/dev/null || skip "no realdata"
        cp "$src/../shared/realdata/robot_kinect_frames/calib/17.yaml" "$tmp/one/calib/"
        real=$tmp/one pattern="one: noise-stats needs two frames of a static camera, the recording has 1" ;;
      noise_stats_not_a_recording) printf 'not a bag\n' >"$tmp/text.bag"; real=$tmp/text.bag pattern="text\.bag" ;;
    esac
    run_bench noise-stats --real "$real" --out "$tmp/out/stats.json"
    expect_rc 2
    expect_error_line "$pattern"
    [[ ! -e "$tmp/out/stats.json" ]] || fail "wrote stats.json"
    ;;

  noise_occlusion_bad_margin)
    # A negative margin of the stereo-occlusion artifacts names file, line and key.
    sed "s#^  noise: {enabled: true}#  noise: {enabled: true, stereo_occlusion: true, left_band_margin_px: -3}#" "$scenario" >"$tmp/s.yaml"
    sed -i "s#^world: .*#world: $src/worlds/office_corridor.xml#" "$tmp/s.yaml"
    line=$(grep -n "left_band_margin_px: -3" "$tmp/s.yaml" | cut -d: -f1)
    [[ -n "$line" ]] || fail "no noise line in office_corridor.yaml"
    run_bench run "$tmp/s.yaml" --out "$tmp/out" --no-progress --duration 1
    expect_rc 2
    expect_error_line "s\.yaml:$line: camera\.noise\.left_band_margin_px: .*must be finite and >= 0"
    expect_no_results "$tmp"
    ;;

  *)
    echo "faults.sh: unknown case '$case_name'" >&2
    exit 2
    ;;
esac
echo "PASS [$case_name]"
