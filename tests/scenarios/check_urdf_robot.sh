#!/usr/bin/env bash
# scenarios/urdf_robot.yaml (issue 29): its run (METRICS, the scenario.urdf_robot fixture) drove example_bot with the
# physics, the auto probe having passed, with the wheels found and the footprint from the URDF's collision shapes;
# then the same scenario with robot.drive: kinematic must pass its checks and reach the path's end.
# Usage: check_urdf_robot.sh BIN METRICS OUT SCENARIO
set -euo pipefail
bin=$1 metrics=$2 out=$3 scenario=$4
expect_robot() {  # METRICS DRIVE REASON_PREFIX
  /usr/bin/python3 - "$@" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
r = m.get("robot", {})
checks = {
    "drive": r.get("drive") == sys.argv[2],
    "drive_reason": r.get("drive_reason", "").startswith(sys.argv[3]),
    "wheels found": r.get("wheels", {}).get("how") == "found",
    "footprint from the URDF": r.get("footprint_source", "").startswith("URDF collision shapes"),
    "passed": m["passed"],
    "path completed": any(c["name"] == "path_completed" and c["status"] == "pass" for c in m["checks"]),
}
for name, ok in checks.items():
    print(f"{'PASS' if ok else 'FAIL'}: {m['scenario']} {name}")
print("  robot:", json.dumps(r))
sys.exit(0 if all(checks.values()) else 1)
PY
}
expect_robot "$metrics" physics "auto: the physics probe drove"
rm -rf "$out" && mkdir -p "$(dirname "$out")"
"$bin" run "$scenario" --out "$out" --no-progress --set robot.drive=kinematic >"$out.log" 2>&1 || { cat "$out.log"; exit 1; }
grep -q "^drive: kinematic (robot.drive: kinematic)$" "$out.log" || { echo "FAIL: no drive line"; cat "$out.log"; exit 1; }
expect_robot "$out/metrics.json" kinematic "robot.drive: kinematic"
