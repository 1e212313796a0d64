#!/usr/bin/env bash
# A failure-mode scenario must keep reproducing STVL's failure once our fix is switched off: runs SCENARIO with
# the given --set assignments (STVL's behaviour) and requires the Python expression EXPECT, over the run's
# metrics.json as `m`, to hold. Usage: check_stvl_behaviour.sh BIN OUT SCENARIO EXPECT [--set KEY=VALUE ...]
set -euo pipefail
bin=$1 out=$2 scenario=$3 expect=$4
shift 4
rm -rf "$out" && mkdir -p "$(dirname "$out")"
rc=0
"$bin" run "$scenario" --out "$out" --no-progress "$@" >"$out.log" 2>&1 || rc=$?
if ((rc == 2)); then echo "FAIL: the run was refused"; cat "$out.log"; exit 1; fi
/usr/bin/python3 - "$out/metrics.json" "$expect" <<'PY'
import json, sys
m = json.load(open(sys.argv[1]))
e = m["evaluation"]
ok = eval(sys.argv[2], {"m": m, "e": e})
print(f"{'PASS' if ok else 'FAIL'}: STVL's behaviour ({m['scenario']}): {sys.argv[2]}")
print("  final phantoms:", e["final"]["phantom_obstacles"], e["final"]["phantoms"])
print("  failure_modes:", json.dumps(e.get("failure_modes", {})))
sys.exit(0 if ok else 1)
PY
