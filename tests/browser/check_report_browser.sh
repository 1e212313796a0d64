#!/usr/bin/env bash
# report.html in a real browser: a short run of the default corridor, then headless Chromium (Debian's) loads its
# report.html. The page must log no script error, every chart canvas and the 3D view must have painted pixels
# (the page counts them itself once drawn: <pre id="selftest">), the checks table must say what metrics.json
# says, and every picture must be inlined (one self-contained file). Leaves report.png (a screenshot) beside the report.
# A closed-loop scenario adds the drive's chart (speed, turn rate, events) in its "Closed loop" section; camera
# timing (camera.timing, tf) adds the delays and drops chart.
# With a recording (a bag or PNG folder) instead of a scenario: its replay's report, which has no quality chart
# and no checks, says it has no ground truth, and shows the map's voxels unjudged.
set -euo pipefail
bin=$1 out=$2 input=$3
rm -rf "$out" && mkdir -p "$out"
command -v chromium >/dev/null || { echo "FAIL: chromium is not installed (scripts/install-deps.sh installs it)"; exit 1; }
if [[ $input == *.yaml ]]; then
  "$bin" run "$input" --duration 4 --out "$out/run" --no-progress >"$out/run.log" 2>&1 || true
else
  [[ -e $input ]] || { echo "SKIP: no $input"; exit 77; }
  "$bin" replay "$input" --out "$out/run" --no-progress >"$out/run.log" 2>&1 || true
fi
[[ -f "$out/run/report.html" ]] || { echo "FAIL: the run wrote no report.html"; cat "$out/run.log"; exit 1; }
browser=(chromium --headless=new --no-sandbox --disable-gpu --use-gl=swiftshader --enable-unsafe-swiftshader
         --window-size=1400,4000 --user-data-dir="$out/profile")
url="file://$(realpath "$out/run/report.html")"
timeout 120 "${browser[@]}" --enable-logging=stderr --v=0 --dump-dom "$url" >"$out/dom.html" 2>"$out/browser.log"
timeout 120 "${browser[@]}" --screenshot="$out/run/report.png" "$url" >/dev/null 2>&1 || true
if grep -E "CONSOLE.*(Uncaught|Error)" "$out/browser.log" | grep -v "GL Driver Message"; then
  echo "FAIL: the page logged errors (above)"; exit 1
fi
/usr/bin/python3 - "$out/dom.html" "$out/run/metrics.json" <<'PY'
import html, json, re, sys
dom = open(sys.argv[1]).read()
metrics = json.load(open(sys.argv[2]))
m = re.search(r'<pre id="selftest"[^>]*>(.*?)</pre>', dom, re.S)
assert m and m.group(1).strip(), "the page did not finish drawing (empty selftest)"
t = json.loads(html.unescape(m.group(1)))
assert t["errors"] == [], f"script errors: {t['errors']}"
charts = t["charts"]
replay = metrics.get("kind") == "replay"
expected_charts = ["chart-points", "chart-stages", "chart-voxels"] + ([] if replay else ["chart-quality"])
if "frame_timing" in metrics:  # camera timing: the delays and drops chart
    expected_charts.append("chart-timing")
closed_loop = metrics.get("navigation", {}).get("mode") == "closed_loop"
if closed_loop:  # the drive's chart in the "Closed loop" section
    expected_charts.append("chart-drive")
    assert "<h2>Closed loop" in dom, "a closed-loop run's report must have its Closed loop section"
assert sorted(charts) == sorted(expected_charts), charts
for name, painted in charts.items():
    assert painted > 2000, f"{name}: only {painted} painted pixels"
assert t["view3d"] > 2000, f"3D view: only {t['view3d']} painted pixels"
if replay:
    assert t["view3d_points"]["unjudged"] > 0 and t["view3d_points"]["tp"] == 0, t["view3d_points"]
    assert "No ground truth" in dom and "<h2>Checks</h2>" not in dom, "the replay's report must say it has no truth"
    frames = re.search(r"<th>frames</th><td>(\d+) replayed", dom)
    assert frames and int(frames.group(1)) == metrics["frames"], "the recording table's frames != metrics.json"
    print(f"PASS: replay report: charts {charts}, 3D view {t['view3d']} px, {t['view3d_points']['unjudged']} voxels")
    sys.exit(0)
assert t["view3d_points"]["tp"] > 0 and t["view3d_points"]["truth"] > 0, t["view3d_points"]
table = re.search(r"<h2>Checks</h2><table>(.*?)</table>", dom, re.S).group(1)
rows = re.findall(r"<tr><td>(.*?)</td><td[^>]*>(pass|FAIL|not evaluated)</td>", table)
label = {"pass": "pass", "fail": "FAIL", "not_evaluated": "not evaluated"}  # a 4 s run: path_completed not evaluated
expected = [(c["name"], label[c["status"]]) for c in metrics["checks"]]
assert [(html.unescape(n), r) for n, r in rows] == expected, f"checks table {rows} != metrics.json {expected}"
imgs = re.findall(r'<img[^>]* src="([^"]{0,40})', dom)
assert imgs and all(src.startswith("data:image/png;base64,") for src in imgs), f"pictures not inlined: {imgs}"
print(f"PASS: charts {charts}, 3D view {t['view3d']} px, {len(rows)} checks as in metrics.json, {len(imgs)} inlined pictures")
PY
