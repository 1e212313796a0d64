#!/usr/bin/env bash
# The robot seeing itself (STVL issue #214): scenarios/robot_sees_itself.yaml with STVL's footprint clearing
# turned off must reproduce the failure (lethal cells on the robot's own bumper, the self_lethal_cells check
# failing, exit 1); with it on (the file as shipped) none, while the bumper's voxels stay in the map (STVL frees
# the costmap's cells only).
set -euo pipefail
bin=$1 out=$2
here=$(dirname "$0")
scenario=$here/../../scenarios/robot_sees_itself.yaml
rm -rf "$out" && mkdir -p "$out"
rc=0
"$bin" run "$scenario" --out "$out/off" --no-progress --set map.update_footprint_enabled=false >"$out/off.log" || rc=$?
[[ $rc -eq 1 ]] || { echo "FAIL: without footprint clearing the run exited $rc, expected 1 (a failed check)"; cat "$out/off.log"; exit 1; }
grep -q "^FAIL self_lethal_cells" "$out/off.log" || { echo "FAIL: the self_lethal_cells check did not fail"; cat "$out/off.log"; exit 1; }
"$bin" run "$scenario" --out "$out/on" --no-progress >"$out/on.log" ||
  { echo "FAIL: with footprint clearing the scenario failed"; cat "$out/on.log"; exit 1; }
/usr/bin/python3 - "$out" <<'PY'
import json, struct, sys
out = sys.argv[1]
off = json.load(open(f"{out}/off/metrics.json"))["evaluation"]["failure_modes"]["self_marking"]
on = json.load(open(f"{out}/on/metrics.json"))["evaluation"]["failure_modes"]["self_marking"]
assert off["max_self_lethal_cells"] > 0 and off["final_inside"] > 0, f"fix off: no self-marking reproduced: {off}"
assert on["max_self_lethal_cells"] == 0, f"fix on: self-marking left: {on}"
# The voxels of the bumper (0.215..0.255 m ahead of base_link, 0.05..0.13 m high) stay in the map.
data = open(f"{out}/on/map.ply", "rb").read()
header, _, body = data.partition(b"end_header\n")
n = int([l for l in header.split(b"\n") if l.startswith(b"element vertex")][0].split()[2])
low = [struct.unpack_from("<fffd", body, 20 * i) for i in range(n)]
low = [p for p in low if abs(p[1]) < 0.15 and 0.05 < p[2] < 0.15 and p[0] < 0.6]
assert low, "fix on: no bumper voxels in the map (STVL keeps them; only the costmap is freed)"
print(f"self-marking: fix off {off['max_self_lethal_cells']} lethal cells on the robot "
      f"({off['max_inside']} inside, {off['max_ring']} ring), fix on 0; {len(low)} bumper voxels kept in the map")
PY
