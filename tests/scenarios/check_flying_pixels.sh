#!/usr/bin/env bash
# scenarios/flying_pixels.yaml with the edge filter off on both cameras (STVL's behaviour, which has no such
# filter): the flying pixels must still leave phantom obstacles in the final costmap, so that the scenario
# keeps reproducing the failure its filter-on run (scenario.flying_pixels) shows gone. Figures from metrics.json.
set -euo pipefail
bin=$1 out=$2
here=$(dirname "$0")
rm -rf "$out" && mkdir -p "$out"
rc=0
"$bin" run "$here/../../scenarios/flying_pixels.yaml" --out "$out/off" --no-progress \
  --set 'robot.cameras[0].edge_filter.enabled=false' --set 'robot.cameras[1].edge_filter.enabled=false' \
  >"$out/off.log" 2>&1 || rc=$?
# 1: a check failed (the phantom check is expected to); anything else is an error of the run itself.
[[ $rc -eq 0 || $rc -eq 1 ]] || { cat "$out/off.log"; echo "FAIL: run exited $rc"; exit 1; }
/usr/bin/python3 - "$out/off/metrics.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
final = m["evaluation"]["final"]
phantoms = final["phantom_obstacles"]
print("edge filter off: %d phantom obstacles in the final costmap %s, at most %d at one evaluation" % (
    phantoms, [(p["cells"], round(p["x_m"], 2), round(p["y_m"], 2)) for p in final["phantoms"]],
    m["evaluation"]["mean"]["max_phantom_obstacles"]))
if phantoms < 1:
    print("FAIL: no phantom without the edge filter: the scenario no longer reproduces STVL issue #141")
    sys.exit(1)
PY
