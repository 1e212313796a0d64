#!/usr/bin/env bash
# rosbag2 files as ROS 2 itself writes them replay to the map of the plain recording (CTest
# recording.ros2_recordings, label unit):
#  - a short run's export (depth, camera_info, /tf, /tf_static, /odom), and the real D435 recording of
#    ../shared/realdata re-exported by a replay as rosbag2, each rewritten by mcap_js/ros2_variants.cjs
#    (@mcap/core) with the schemas `ros2 bag record` embeds: the .msg files of ../shared/ros2_msgs, comments,
#    constants and defaults and all, concatenated as rosbag2 does (/odom keeps the export's schema:
#    nav_msgs/Odometry is not there); and once more with every kind of topic a replay must skip beside the camera's
#    (a service event, action feedback and status, JSON with a jsonschema, a ros2idl schema, protobuf, a channel
#    without schema, a ros2msg schema that does not parse, a pkg/idl/Type);
#  - their sqlite3 twins written by write_db3_variants.py (Python's sqlite3): Jazzy's tables with
#    message_definitions, the skipped topics as sqlite3 has them, and Humble's schema-free copy, the reference;
#  - each replays with exit 0 to the reference's map.ply byte for byte, and `replay --list-topics` lists each
#    skipped topic with its message count and "not read";
#  - the recordings of rosbag2's own tests (../shared/realdata/rosbag2: no depth in them) list every topic as not
#    read with --list-topics (exit 0) and, replayed, exit 2 saying there is no depth topic and naming them.
# Usage: check_ros2_recordings.sh STVL_BENCH SOURCE_DIR OUT_DIR. Exit 77 (skip) without node/npm, the packages
# (npm ci of mcap_js/ into OUT_DIR/npm) or ../shared beside the checkout.
set -uo pipefail
bench=$1 src=$2 out=$3
here=$src/tests/recording
msgs=$src/../shared/ros2_msgs real=$src/../shared/realdata/rosbag2
[[ -d $msgs && -d $real ]] || { echo "SKIP: no $msgs or $real (../shared beside the checkout)"; exit 77; }
source "$here/mcap_js_env.sh"  # node, npm ci of mcap_js/, NODE_PATH, $w, fail, ok

# 1. The recordings and their variants: a run's export (a simulated D435), and the real D435's two frames
# (../shared/realdata/d435_office_corner, librealsense's ROS 1 bag) re-exported by a replay as rosbag2.
"$bench" run --duration 2 --out "$w/run" --bag "$w/x.mcap" --no-progress \
  --bag-topics '/camera/depth/image_rect_raw,/camera/depth/camera_info,/tf*,/odom' >"$w/run.log" 2>&1 || {
  echo "FAIL: the run: $(tail -3 "$w/run.log")"; exit 1; }
d435=$src/../shared/realdata/d435_office_corner/single_depth_color_640x480.bag
"$bench" replay "$d435" --out "$w/d435_ros1" --bag "$w/d435.mcap" --no-progress \
  --bag-topics '/camera/depth/image_rect_raw,/camera/depth/camera_info,/tf*' >"$w/d435.log" 2>&1 || {
  echo "FAIL: the D435 re-export: $(tail -3 "$w/d435.log")"; exit 1; }

# 2. Each variant replays to its Humble reference's map; the skipped topics are named.
check_variants() {  # NAME ROSBAG2_FOLDER
  local name=$1 bag=$2 v=$w/$1 rec frames missing skipped
  node "$here/mcap_js/ros2_variants.cjs" "$bag/$(basename "$bag")_0.mcap" "$msgs" "$v" >"$v.log" 2>&1 &&
    /usr/bin/python3 "$here/write_db3_variants.py" "$v" >>"$v.log" 2>&1 || {
    fail "$name: writing the variants: $(tail -5 "$v.log")"; return; }
  sed 's/^/  /' "$v.log"
  skipped=$(/usr/bin/python3 -c 'import json, sys; print(" ".join(t["topic"] for t in json.load(open(sys.argv[1])) if t["skipped"]))' "$v/dump.json")
  "$bench" replay "$v/humble.db3" --out "$v/ref" --no-progress >"$v/ref.log" 2>&1 && [[ -s $v/ref/map.ply ]] || {
    fail "$name: the Humble reference: $(tail -3 "$v/ref.log")"; return; }
  ok "$name reference: $(grep '^replay: ' "$v/ref.log" | head -1 | cut -c1-160)"
  for variant in jazzy.mcap jazzy.db3 skip.mcap skip.db3 export; do
    [[ $variant == export ]] && rec=$bag || rec=$v/$variant
    if ! "$bench" replay "$rec" --out "$v/rep_$variant" --no-progress >"$v/rep_$variant.log" 2>&1; then
      fail "$name replay $variant: $(tail -2 "$v/rep_$variant.log")"
      continue
    fi
    cmp -s "$v/rep_$variant/map.ply" "$v/ref/map.ply" && ok "$name replay $variant: map.ply = the reference's" ||
      fail "$name replay $variant: map.ply differs"
    [[ $variant == skip.* ]] || continue
    "$bench" replay "$rec" --list-topics >"$v/list_$variant.log" 2>&1 ||
      fail "$name replay --list-topics $variant: exit $?, $(tail -2 "$v/list_$variant.log")"
    # The listing: "  TOPIC  TYPE  N message(s)  ENCODINGS  not read[: why]", one line a topic; each skipped topic
    # has one message per depth frame.
    frames=$(sed -n 's/^replay reads \([0-9]*\) depth frames.*/\1/p' "$v/list_$variant.log")
    missing=""
    for topic in $skipped; do
      awk -v t="$topic" -v n="$frames" '$1 == t && $0 ~ ("  " n " message\\(s\\)  .*  not read") { found = 1 } END { exit !found }' \
        "$v/list_$variant.log" || missing+=" $topic"
    done
    [[ -n $frames && -z $missing ]] && ok "$name $variant: every skipped topic listed, $frames messages, not read" ||
      fail "$name $variant: not listed as skipped:$missing (frames '$frames')"
  done
}
check_variants run "$w/x"
check_variants d435 "$w/d435"

# 3. rosbag2's own recordings: listed, and without depth refused naming their topics.
topics_of() {  # the topic names of a rosbag2 folder: its .db3 files' topics tables, else metadata.yaml
  /usr/bin/python3 - "$1" <<'PY'
import glob, re, sqlite3, sys
names = set()
for db in glob.glob(sys.argv[1] + "/*.db3"):
    names |= {row[0] for row in sqlite3.connect("file:%s?mode=ro" % db, uri=True).execute("SELECT name FROM topics")}
if not names:
    names = set(re.findall(r"^\s+name: (\S+)$", open(sys.argv[1] + "/metadata.yaml").read(), re.M))
print(" ".join(sorted(names)))
PY
}
for bag in "$real"/*/; do
  name=$(basename "$bag") topics=$(topics_of "$bag")
  [[ -n $topics ]] || { fail "$name: no topics found by the test"; continue; }
  "$bench" replay "$bag" --list-topics >"$w/real_list_$name.log" 2>&1
  rc=$? missing=""
  for topic in $topics; do
    awk -v t="$topic" '$1 == t && / message\(s\)  .*  not read/ { found = 1 } END { exit !found }' \
      "$w/real_list_$name.log" || missing+=" $topic"
  done
  [[ $rc == 0 && -z $missing ]] && ok "$name --list-topics: $topics" ||
    fail "$name --list-topics: exit $rc, not listed:$missing; $(tail -2 "$w/real_list_$name.log")"
  "$bench" replay "$bag" --out "$w/real_$name" --no-progress >"$w/real_$name.log" 2>&1
  rc=$? missing=""
  for topic in $topics; do grep -qF -- "$topic" "$w/real_$name.log" || missing+=" $topic"; done
  [[ $rc == 2 && -z $missing ]] && grep -q "no depth topic" "$w/real_$name.log" && ok "$name: exit 2, no depth topic" ||
    fail "$name: exit $rc, not named:$missing; $(grep error "$w/real_$name.log" | cut -c1-200)"
done
echo "$failures failure(s)"
# The recordings are deleted once every check passes (CI disk); a failure keeps them.
[[ $failures == 0 ]] && rm -rf "$w"
