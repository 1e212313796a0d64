#!/usr/bin/env bash
# rosbag2 in and out, against independent implementations (CTest replay.ros2_interop, label unit):
#  - every export (zstd, lz4, none; default and all topics) read by @mcap/core + @mcap/nodejs (stream reader with
#    CRCs, indexed reader through the summary) and every message decoded by @foxglove/rosmsg2-serialization from
#    the schema in the file (mcap_js/verify_mcap.cjs);
#  - recordings written by @mcap/core (zstd chunks, with and without summary, 16UC1 and 32FC1) and .db3 files
#    written by Python's sqlite3 (Humble and Jazzy schemas) replayed;
#  - bad input exits 2 with a clear message; a file cut short replays up to its last whole record with a warning;
#  - round trip: run -> MCAP -> replay gives the same map as run -> ROS 1 bag -> replay.
# Usage: check_ros2_interop.sh STVL_BENCH SOURCE_DIR OUT_DIR. Exit 77 (skip) without node/npm or the packages.
set -uo pipefail
bench=$1 src=$2 out=$3
here=$src/tests/recording
source "$here/mcap_js_env.sh"  # node, npm ci of mcap_js/, NODE_PATH, $w, fail, ok

# 1. Exports, read by the reference library.
"$bench" run --duration 2 --out "$w/run" --bag "$w/z.mcap" --no-progress >"$w/run.log" 2>&1
"$bench" run --duration 2 --out "$w/run_l" --bag "$w/l.mcap" --bag-compression lz4 --bag-topics all --no-progress >/dev/null 2>&1
"$bench" run --duration 2 --out "$w/run_n" --bag "$w/n" --bag-format ros2 --bag-compression none \
  --bag-topics '/camera/depth/image_rect_raw,/camera/depth/camera_info,/tf*' --no-progress >/dev/null 2>&1
for case in "z/z_0.mcap default" "l/l_0.mcap all" "n/n_0.mcap listed"; do
  set -- $case
  if node "$here/mcap_js/verify_mcap.cjs" "$w/$1" >"$w/$2.json" 2>"$w/$2.err"; then
    /usr/bin/python3 - "$w/$2.json" "$2" <<'PY' && ok "export $2 read and decoded by @mcap/core + rosmsg2-serialization" || fail "export $2: topics"
import json, sys
d = json.load(open(sys.argv[1])); t = d["topics"]; kind = sys.argv[2]
need = {"/camera/depth/image_rect_raw", "/camera/depth/camera_info", "/tf", "/tf_static"}
if kind != "listed": need |= {"/stvl/filtered_points", "/stvl/voxel_grid", "/stvl/costmap", "/odom", "/clock"}
assert need <= set(t), sorted(need - set(t))
assert ("/camera/depth/points" in t) == (kind == "all"), "full clouds only with all"
if kind == "listed": assert set(t) == {"/camera/depth/image_rect_raw", "/camera/depth/camera_info", "/tf", "/tf_static"}, sorted(t)
assert t["/tf_static"]["durability"] == "transient_local" and t["/tf"]["durability"] == "volatile"
assert t["/camera/depth/image_rect_raw"]["first"]["encoding"] == "16UC1"
assert d["chunks"] >= 1 and d["messages"] == sum(x["count"] for x in t.values())
print("  %s: %d messages in %d chunks, %d topics" % (kind, d["messages"], d["chunks"], len(t)))
PY
  else
    fail "export $2: $(tail -3 "$w/$2.err")"
  fi
done
grep -q "version: 9" "$w/z/metadata.yaml" && grep -q "relative_file_paths" "$w/z/metadata.yaml" && ok "metadata.yaml" || fail "metadata.yaml"

# 2. Files written by others, replayed.
expect_replay() {  # NAME PATTERN ARGS...
  local name=$1 pattern=$2; shift 2
  if "$bench" replay "$@" --out "$w/rep_$name" --no-progress >"$w/rep_$name.log" 2>&1 && grep -Eq "$pattern" "$w/rep_$name.log"; then
    ok "replay $name: $(grep '^replay: ' "$w/rep_$name.log" | head -1 | cut -c1-150)"
  else
    fail "replay $name: $(tail -3 "$w/rep_$name.log")"
  fi
}
node "$here/mcap_js/write_mcap.cjs" "$w/js16.mcap" 16UC1 zstd && expect_replay js16 "5 frames 64x48.*" "$w/js16.mcap"
node "$here/mcap_js/write_mcap.cjs" "$w/js32.mcap" 32FC1 zstd nosummary && expect_replay js32 "32FC1, poses: tf\): 5 frames" "$w/js32.mcap"
node "$here/mcap_js/write_mcap.cjs" "$w/jsnone.mcap" 16UC1 none && expect_replay jsnone "5 frames" "$w/jsnone.mcap" --fixed-frame odom
/usr/bin/python3 "$here/write_db3.py" "$w/humble.db3" humble && expect_replay humble "rosbag2 \(sqlite3\), 16UC1, poses: tf\): 4 frames" "$w/humble.db3"
/usr/bin/python3 "$here/write_db3.py" "$w/jazzy.db3" jazzy && expect_replay jazzy "poses: odometry\): 4 frames" "$w/jazzy.db3" --odom-topic /odom
mkdir -p "$w/jazzy_folder" && cp "$w/jazzy.db3" "$w/jazzy_folder/" && expect_replay jazzy_folder "4 frames" "$w/jazzy_folder" --odom-topic /odom

# 3. Cut short: up to the last whole record, with a warning.
size=$(stat -c %s "$w/z/z_0.mcap")
head -c $((size * 6 / 10)) "$w/z/z_0.mcap" >"$w/cut.mcap"
expect_replay cut "frames" "$w/cut.mcap"
grep -q "warning: .*cut short" "$w/rep_cut.log" && ok "cut short: warned" || fail "cut short: no warning"

# 4. Bad input: exit 2 and a clear message.
expect_error() {  # NAME PATTERN PATH
  "$bench" replay "$3" --out "$w/bad_$1" --no-progress >"$w/bad_$1.log" 2>&1
  local rc=$?
  if [[ $rc == 2 ]] && grep -Eq "$2" "$w/bad_$1.log"; then ok "bad input $1: $(grep error "$w/bad_$1.log" | cut -c1-160)"
  else fail "bad input $1: exit $rc, $(tail -2 "$w/bad_$1.log")"; fi
  [[ ! -e $w/bad_$1/metrics.json ]] || fail "bad input $1 left a metrics.json"
}
printf 'not an mcap file at all' >"$w/magic.mcap" && expect_error magic "bad magic" "$w/magic.mcap"
cp "$w/n/n_0.mcap" "$w/crc.mcap" && printf '\x55\x55\x55\x55' | dd of="$w/crc.mcap" bs=1 seek=$((size / 3)) conv=notrunc status=none
expect_error crc "CRC mismatch|runs past|malformed" "$w/crc.mcap"
node "$here/mcap_js/write_mcap.cjs" "$w/schema.mcap" 16UC1 zstd badschema && expect_error schema "does not parse" "$w/schema.mcap"
node "$here/mcap_js/write_mcap.cjs" "$w/short.mcap" 16UC1 zstd short && expect_error short "too short" "$w/short.mcap"
/usr/bin/python3 - "$w/z/z_0.mcap" "$w/compression.mcap" <<'PY'
import sys
data = bytearray(open(sys.argv[1], "rb").read())
i = data.index(b"zstd")  # the first chunk's compression field
data[i:i + 4] = b"zzzz"
open(sys.argv[2], "wb").write(data)
PY
expect_error compression "unknown compression 'zzzz'" "$w/compression.mcap"
/usr/bin/python3 - "$w/z/z_0.mcap" "$w/length.mcap" <<'PY'
import struct, sys
data = bytearray(open(sys.argv[1], "rb").read())
i = data.index(b"\x06", 8 + 9 + struct.unpack_from("<Q", data, 9)[0])  # the first chunk after the header
struct.pack_into("<Q", data, i + 1, len(data) * 2)
open(sys.argv[2], "wb").write(data)
PY
expect_error length "runs past the end" "$w/length.mcap"
/usr/bin/python3 "$here/write_db3.py" "$w/nomsg.db3" humble nomessages && expect_error nomessages "no messages table" "$w/nomsg.db3"
# A type named as ROS 1 names it (sensor_msgs/Image) is read by that name.
/usr/bin/python3 "$here/write_db3.py" "$w/badtype.db3" humble badtype && expect_replay badtype "4 frames" "$w/badtype.db3"
cp -r "$w/z" "$w/missing" && rm "$w/missing/z_0.mcap" && expect_error missing "names z_0.mcap, which is missing" "$w/missing"

# 5. Round trip: the same run as a ROS 1 bag and as MCAP, each replayed.
"$bench" run --duration 3 --out "$w/rt1" --bag "$w/rt.bag" --no-progress >/dev/null 2>&1
"$bench" run --duration 3 --out "$w/rt2" --bag "$w/rt.mcap" --no-progress >/dev/null 2>&1
"$bench" replay "$w/rt.bag" --out "$w/rt_ros1" --no-progress >"$w/rt_ros1.log" 2>&1
"$bench" replay "$w/rt" --out "$w/rt_ros2" --no-progress >"$w/rt_ros2.log" 2>&1
/usr/bin/python3 - "$w/rt_ros1" "$w/rt_ros2" <<'PY' && ok "round trip: MCAP replay = ROS 1 replay" || fail "round trip differs"
import json, sys
a, b = (json.load(open(d + "/metrics.json")) for d in sys.argv[1:3])
ka = {k: v for k, v in a.items() if "time" not in k and "wall" not in k and not isinstance(v, (dict, list))}
kb = {k: v for k, v in b.items() if "time" not in k and "wall" not in k and not isinstance(v, (dict, list))}
ka.pop("real_time_factor", None); kb.pop("real_time_factor", None)
assert ka == kb, {k: (ka.get(k), kb.get(k)) for k in set(ka) | set(kb) if ka.get(k) != kb.get(k)}
pa, pb = (open(d + "/map.ply", "rb").read() for d in sys.argv[1:3])
assert pa == pb, "map.ply differs"
print("  identical: map.ply byte for byte and every scalar of metrics.json but timings")
PY
echo "$failures failure(s)"
# The recordings are deleted once every check passes (about 0.5 GB; CI disk); a failure keeps them.
[[ $failures == 0 ]] && rm -rf "$w"
