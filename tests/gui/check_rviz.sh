#!/usr/bin/env bash
# report/stvl.rviz for real: a short run's bag played into RViz (Debian's rviz, roscore, rosbag) under Xvfb, and a
# screenshot of the window. The config is used as shipped except that only the STVL voxel display stays on,
# drawn in one flat colour, so the test can count its pixels: the 3D view (the main panel, nearly the whole
# window) must show many of them; with the voxel display off too it must show none (the colour comes from the
# voxels). Skips (77) only where Xvfb cannot start.
set -euo pipefail
bin=$1 out=$2 config=$3
rm -rf "$out" && mkdir -p "$out"
for tool in Xvfb roscore rosparam rostopic rosbag rviz xwd xwdtopnm; do
  command -v "$tool" >/dev/null || { echo "FAIL: $tool is not installed (scripts/install-deps.sh installs it)"; exit 1; }
done
"$bin" run --duration 3 --out "$out/run" --bag "$out/run.bag" --no-progress >"$out/run.log" 2>&1 || true
[[ -f "$out/run.bag" ]] || { echo "FAIL: the run wrote no bag"; cat "$out/run.log"; exit 1; }

pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; }
trap cleanup EXIT
Xvfb -displayfd 3 -screen 0 1600x1000x24 3>"$out/display" >"$out/xvfb.log" 2>&1 &
pids+=($!)
for _ in $(seq 50); do [[ -s "$out/display" ]] && break; sleep 0.1; done
[[ -s "$out/display" ]] || { echo "SKIP: Xvfb could not start: $(cat "$out/xvfb.log")"; exit 77; }
export DISPLAY=":$(cat "$out/display")"
port=$((20000 + $$ % 20000))
export ROS_MASTER_URI="http://127.0.0.1:$port" ROS_HOSTNAME=127.0.0.1 ROS_HOME="$out/ros"
roscore -p "$port" >"$out/roscore.log" 2>&1 &
pids+=($!)
for _ in $(seq 100); do rosparam set use_sim_time true 2>/dev/null && break; sleep 0.2; done

shot() {  # NAME VOXELS_ON: plays the bag into RViz and counts the voxel colour's pixels in the window
  local name=$1 on=$2
  /usr/bin/python3 - "$config" "$out/$name.rviz" "$on" <<'PY'
import sys, yaml
config = yaml.safe_load(open(sys.argv[1]))
for d in config["Visualization Manager"]["Displays"]:
    voxels = d.get("Name", "").startswith("STVL voxels")
    d["Enabled"] = voxels and sys.argv[3] == "on"
    if voxels:
        d["Color Transformer"], d["Color"] = "FlatColor", "255; 0; 255"
config["Visualization Manager"]["Global Options"]["Background Color"] = "48; 48; 48"
yaml.safe_dump(config, open(sys.argv[2], "w"))
PY
  rviz -d "$out/$name.rviz" >"$out/$name.rviz.log" 2>&1 &
  local viz=$!
  pids+=($viz)
  # Play only once RViz listens (its displays subscribe when they are built), then give it time to draw.
  local topic=/tf
  [[ $on == on ]] && topic=/stvl/voxel_grid
  for _ in $(seq 120); do
    rostopic info "$topic" 2>/dev/null | grep -q "/rviz" && break
    sleep 0.5
  done
  sleep 3
  rosbag play --clock -q "$out/run.bag" >"$out/$name.play.log" 2>&1
  sleep 2
  xwd -root -silent | xwdtopnm 2>/dev/null >"$out/$name.ppm"
  kill "$viz" 2>/dev/null || true
  wait "$viz" 2>/dev/null || true
  /usr/bin/python3 - "$out/$name.ppm" <<'PY'
import sys
data = open(sys.argv[1], "rb").read()
fields, at = [], 0
while len(fields) < 4:  # P6 width height maxval, whitespace-separated
    while data[at:at + 1].isspace(): at += 1
    start = at
    while not data[at:at + 1].isspace(): at += 1
    fields.append(data[start:at])
w, h, maxval = int(fields[1]), int(fields[2]), int(fields[3])
size = 2 if maxval > 255 else 1  # xwdtopnm writes 16-bit samples (big-endian, high byte first)
pixels = data[at + 1:]
count = 0
for y in range(60, h - 40):  # the 3D view: below the toolbar, above the status bar
    row = pixels[3 * size * w * y: 3 * size * w * (y + 1)]
    for x in range(20, w - 20):
        r, g, b = (row[(3 * x + c) * size] for c in range(3))
        count += r > 120 and b > 120 and g < 90 and abs(r - b) < 100
print(count)
PY
}
with=$(shot voxels on)
without=$(shot none off)
echo "voxel-coloured pixels in the 3D view: $with with the voxel display, $without without"
((with > 5000)) || { echo "FAIL: RViz drew too few voxels ($with pixels)"; exit 1; }
((without < 50)) || { echo "FAIL: $without voxel-coloured pixels without the voxel display"; exit 1; }
rm -f "$out/run.bag"  # 250 MB of CI disk; a failing run keeps it
echo "PASS: RViz shows the bag's STVL voxels in the main 3D view"
