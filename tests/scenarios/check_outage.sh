#!/usr/bin/env bash
# scenarios/camera_outage.yaml really had its outage, and STVL's buffer behaviour during it, from its
# metrics.json (evaluation.failure_modes.outage; the run is the scenario.camera_outage test, this test's fixture):
#   - no frame of front_camera inside [from_s, to_s), and every frame time of the window counted as skipped;
#   - the front source's stale time: from its last frame before the outage + expected_update_rate to its first
#     frame after, to 1e-6 s; the other sources never stale;
#   - STVL's figure: at every update of the side cameras during the outage the front source's last reading was
#     applied again (observation_persistence 0 keeps it forever): readings almost as old as the outage, at a
#     pose the robot left metres behind. This is what STVL does; the test fails if the bench stops doing it.
set -euo pipefail
metrics=$1
[[ -f "$metrics" ]] || { echo "FAIL: $metrics missing (run scenario.camera_outage first)"; exit 1; }
/usr/bin/python3 - "$metrics" <<'PY'
import json, math, sys
m = json.load(open(sys.argv[1]))
fails = []
def need(ok, what):
    print(("ok   " if ok else "FAIL ") + what)
    if not ok: fails.append(what)
cams = {c["name"]: c for c in m["evaluation"]["failure_modes"]["outage"]["cameras"]}
rates = {c["name"]: c["rate_hz"] for c in m["cameras"]}
front = cams["front_camera"]
need(len(front["outages"]) == 1, "front_camera has one outage")
o = front["outages"][0]
rate = rates["front_camera"]
period = 1.0 / rate
frames_due = [k * period for k in range(int(m["sim_time_s"] * rate) + 2) if o["from_s"] <= k * period < o["to_s"]]
need(o["frames_in_window"] == 0, "no front_camera frame inside [%g, %g) s: %d" % (o["from_s"], o["to_s"], o["frames_in_window"]))
need(front["skipped_frames"] == len(frames_due),
     "front_camera skipped %d frames, %d fall in the window" % (front["skipped_frames"], len(frames_due)))
src = front["sources"][0]
last_before = max(k * period for k in range(int(o["from_s"] * rate) + 2) if k * period < o["from_s"])
first_after = min(k * period for k in range(int(o["to_s"] * rate) + 2) if k * period >= o["to_s"])
stale_from = last_before + src["expected_update_rate_s"]
need(src["expected_update_rate_s"] > 0, "front source expects a reading every %g s" % src["expected_update_rate_s"])
need(abs(src["first_stale_s"] - stale_from) < 1e-6,
     "front source stale from %.4f s (last frame %.4f s + %g s), reported %.4f s" %
     (stale_from, last_before, src["expected_update_rate_s"], src["first_stale_s"]))
need(abs(src["stale_s"] - (first_after - stale_from)) < 1e-6,
     "front source stale for %.4f s, reported %.4f s" % (first_after - stale_from, src["stale_s"]))
for name in ("left_camera", "right_camera"):
    s = cams[name]["sources"][0]
    need(s["stale_s"] == 0 and s["reapplied_readings"] == 0 and cams[name]["skipped_frames"] == 0,
         "%s never stale, nothing applied again, no frame skipped" % name)
need(o["first_marking_frame_s"] >= 0 and abs(o["first_marking_frame_s"] - first_after) < 1e-6,
     "front_camera marks again at its first frame after the outage (%.4f s): %.4f s" % (first_after, o["first_marking_frame_s"]))
# STVL applies every buffer at every update: once per update time of the side cameras inside the window.
need(src["reapplied_readings"] == len(frames_due),
     "front's last reading applied again at every update of the window: %d times (%d update times)" %
     (src["reapplied_readings"], len(frames_due)))
need(src["max_reapplied_age_s"] >= o["to_s"] - o["from_s"] - 2 * period,
     "the oldest reading applied again was %.3f s old (the outage lasts %g s)" % (src["max_reapplied_age_s"], o["to_s"] - o["from_s"]))
need(src["reapplied_max_distance_m"] > 1.0,
     "and was applied from a pose %.2f m behind the camera (> 1 m)" % src["reapplied_max_distance_m"])
sys.exit(1 if fails else 0)
PY
