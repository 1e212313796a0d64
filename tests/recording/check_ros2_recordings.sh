#!/usr/bin/env bash
# rosbag2 files as ROS 2 itself writes them replay to the map of the plain recording (CTest
# recording.ros2_recordings, label unit):
#  - a short run's export (depth, camera_info, /tf, /tf_static, /odom) rewritten by mcap_js/ros2_variants.cjs
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
command -v node >/dev/null || { echo "SKIP: node is not installed"; exit 77; }
command -v npm >/dev/null || { echo "SKIP: npm is not installed"; exit 77; }
[[ -d $msgs && -d $real ]] || { echo "SKIP: no $msgs or $real (../shared beside the checkout)"; exit 77; }
mkdir -p "$out" && rm -rf "$out"/work && mkdir -p "$out/work" "$out/npm"
if ! cmp -s "$here/mcap_js/package-lock.json" "$out/npm/package-lock.json" || [[ ! -d $out/npm/node_modules ]]; then
  cp "$here/mcap_js/package.json" "$here/mcap_js/package-lock.json" "$out/npm/"
  (cd "$out/npm" && npm ci --no-audit --no-fund >npm.log 2>&1) || { echo "SKIP: npm ci failed (offline?): $(tail -3 "$out/npm/npm.log")"; rm -f "$out/npm/package-lock.json"; exit 77; }
fi
export NODE_PATH=$out/npm/node_modules
w=$out/work failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
ok() { echo "ok: $*"; }

# 1. The export and its variants.
"$bench" run --duration 2 --out "$w/run" --bag "$w/x.mcap" --no-progress \
  --bag-topics '/camera/depth/image_rect_raw,/camera/depth/camera_info,/tf*,/odom' >"$w/run.log" 2>&1 || {
  echo "FAIL: the run: $(tail -3 "$w/run.log")"; exit 1; }
node "$here/mcap_js/ros2_variants.cjs" "$w/x/x_0.mcap" "$msgs" "$w/v" >"$w/variants.log" 2>&1 &&
  /usr/bin/python3 "$here/write_db3_variants.py" "$w/v" >>"$w/variants.log" 2>&1 || {
  echo "FAIL: writing the variants: $(tail -5 "$w/variants.log")"; exit 1; }
sed 's/^/  /' "$w/variants.log"
skipped=$(/usr/bin/python3 -c 'import json, sys; print(" ".join(t["topic"] for t in json.load(open(sys.argv[1])) if t["skipped"]))' "$w/v/dump.json")

# 2. Each replays to the reference's map; the skipped topics are named.
"$bench" replay "$w/v/humble.db3" --out "$w/ref" --no-progress >"$w/ref.log" 2>&1 && [[ -s $w/ref/map.ply ]] || {
  echo "FAIL: the Humble reference: $(tail -3 "$w/ref.log")"; exit 1; }
ok "reference: $(grep '^replay: ' "$w/ref.log" | head -1 | cut -c1-160)"
for v in jazzy.mcap jazzy.db3 skip.mcap skip.db3 x; do
  [[ $v == x ]] && rec=$w/x || rec=$w/v/$v
  if ! "$bench" replay "$rec" --out "$w/rep_$v" --no-progress >"$w/rep_$v.log" 2>&1; then
    fail "replay $v: $(tail -2 "$w/rep_$v.log")"
    continue
  fi
  cmp -s "$w/rep_$v/map.ply" "$w/ref/map.ply" && ok "replay $v: map.ply = the reference's" || fail "replay $v: map.ply differs"
  [[ $v == skip.* ]] || continue
  "$bench" replay "$rec" --list-topics >"$w/list_$v.log" 2>&1 || fail "replay --list-topics $v: exit $?, $(tail -2 "$w/list_$v.log")"
  # The listing: "  TOPIC  TYPE  N message(s)  ENCODINGS  not read[: why]", one line a topic; each skipped topic
  # has one message per depth frame.
  frames=$(sed -n 's/^replay reads \([0-9]*\) depth frames.*/\1/p' "$w/list_$v.log")
  missing=""
  for topic in $skipped; do
    awk -v t="$topic" -v n="$frames" '$1 == t && $0 ~ ("  " n " message\\(s\\)  .*  not read") { found = 1 } END { exit !found }' \
      "$w/list_$v.log" || missing+=" $topic"
  done
  [[ -n $frames && -z $missing ]] && ok "$v: every skipped topic listed, $frames messages, not read" ||
    fail "$v: not listed as skipped:$missing (frames '$frames')"
done

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
[[ $failures == 0 ]]
