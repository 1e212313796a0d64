#!/usr/bin/env bash
# Occluded obstacles erased (STVL #134): scenarios/cart_crossing.yaml with STVL's frustum clearing (the nav2
# tutorial's decay_acceleration 15, set in the file) must reproduce the failure that its ray-cast run checks
# away: true voxels cleared while the camera did not see them, and the box's voxels all gone from the map while
# the cart hides it. The cart hides the whole box from 3.53 s to 9.47 s (the box's front face, x 2.4 m, y +-0.3 m,
# lies within y +-0.107 m at the cart's front face, x 1.05 m, seen from the camera at x 0.3 m; the cart is 1 m
# long) and holds still in front of it from 4 s to 9 s: the box must be gone between 3.5 s and 9 s. Exit code 1
# expected: the file's own check hidden_false_clears_max fails.
set -euo pipefail
bin=$1 out=$2
here=$(dirname "$0")
rm -rf "$out" && mkdir -p "$out"
rc=0
"$bin" run "$here/../../scenarios/cart_crossing.yaml" --out "$out/frustum" --no-progress \
  --set map.clearing_mode=frustum --set map.costmap_timing=stvl >"$out/frustum.log" 2>&1 || rc=$?
[[ $rc -eq 1 ]] || { echo "FAIL: frustum run exited $rc, expected 1 (a failed check)"; tail -n 20 "$out/frustum.log"; exit 1; }
/usr/bin/python3 - "$out/frustum/metrics.json" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
o = m["evaluation"]["failure_modes"]["occlusion"]
checks = {c["name"]: c for c in m["checks"]}
box = next((b for b in o["bodies"] if b["name"] == "box"), None)
problems = []
if o["hidden_false_clears"] <= 0:
    problems.append("no hidden false clears")
if checks.get("hidden_false_clears", {}).get("passed", True):
    problems.append("the check hidden_false_clears did not fail")
if box is None:
    problems.append("no hidden false clear of the box")
elif box["vanished_s"] is None or not 3.5 <= box["vanished_s"] <= 9.0:
    problems.append("the box's voxels did not all go while the cart held still in front of it (vanished_s %s)"
                    % box["vanished_s"])
if problems:
    print("FAIL: frustum clearing did not erase the hidden box:", "; ".join(problems))
    print(json.dumps(o, indent=1))
    sys.exit(1)
print("occlusion (frustum): %d hidden false clears (%d behind a surface, %d out of view), first at %.2f s; "
      "box: %d, gone from the map at %.2f s" % (o["hidden_false_clears"], o["behind_surface"], o["out_of_view"],
      o["first_s"], box["hidden_false_clears"], box["vanished_s"]))
PY
