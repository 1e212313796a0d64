#!/usr/bin/env python3
"""The failure-mode twins in closed loop (issue 41): each scenario driven by nav2 (navigation.mode closed_loop) to a
goal past the failure, once with STVL's behaviour and once with the bench's fix, and what the drive cost in each.

  bench/closed_loop_twins.py --bench build/bin/stvl-bench --out OUT [--only NAME]
  bench/closed_loop_twins.py --worlds STVL_SWEEP OURS_SWEEP   # two `stvl-bench sweep --worlds` folders

Writes OUT/<twin>/<stvl|ours>/metrics.json and prints a Markdown table (docs/fidelity.md, "Closed loop"); with
--worlds, the table over generated offices driven in closed loop under both behaviours.
"""
import glob
import math
import argparse
import json
import os
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
SCENARIOS = os.path.join(HERE, "..", "scenarios")
CLOSED = ["navigation.mode=closed_loop"]

# name: (scenario, common --sets, STVL's --sets, ours --sets, what it shows)
TWINS = {
    "person_in_the_narrows": (
        "person_walks_away.yaml",
        CLOSED + ["navigation.goal=[20.0,0.0,0.0]", "duration_s=90",
                  # the person stands where desk_2 narrows the corridor to two gaps of 0.57 and 0.47 m (the robot
                  # needs 0.59), then walks away at 17 s: no-return pixels leave its old place in STVL's map
                  "moving_bodies[0].keyframes[0].position=[9.8,0.35,0.0]"],
        ["map.observation.clear_on_no_return=false"], [],
        "pixels without a return clear nothing (no-return phantom across a narrow passage)"),
    "phantom_in_doorway": (
        "phantom_in_doorway.yaml", [], ["map.observation.clear_on_no_return=false"], [],
        "pixels without a return clear nothing (the person's old place across the only doorway)"),
    "person_walks_away": (
        "person_walks_away.yaml", CLOSED + ["navigation.goal=[20.0,0.0,0.0]", "duration_s=90"],
        ["map.observation.clear_on_no_return=false"], [],
        "pixels without a return clear nothing (the corridor wide enough beside the phantom)"),
    "far_plane": (
        "far_plane.yaml", CLOSED + ["navigation.goal=[20.0,0.0,0.0]", "duration_s=90"],
        ["map.frustum_geometry=stvl"], [], "STVL's clearing frustum ends at 63 % of max_z"),
    "cart_crossing": (
        "cart_crossing.yaml", CLOSED + ["navigation.goal=[4.0,0.0,0.0]", "duration_s=60"],
        ["map.clearing_mode=frustum", "map.costmap_timing=stvl"], [],
        "frustum clearing erases the box the cart hides"),
    "camera_outage": (
        "camera_outage.yaml", CLOSED + ["navigation.goal=[20.0,0.0,0.0]", "duration_s=90"],
        [], ["map.observation.drop_when_not_current=true"], "a camera that stops for 3 s"),
}

FIGURES = ["success", "time_to_goal_s", "path_length_m", "spl", "stalled_s", "recoveries", "blocked_time_s",
           "unseen_cycles"]


def run(bench, out, name, which, sets):
    folder = os.path.join(out, name, which)
    metrics = os.path.join(folder, "metrics.json")
    if not os.path.exists(metrics):
        scenario = os.path.join(SCENARIOS, TWINS[name][0])
        command = [bench, "run", scenario, "--out", folder, "--no-progress"]
        for s in sets:
            command += ["--set", s]
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode not in (0, 1):
            sys.exit("%s %s failed (%d):\n%s" % (name, which, done.returncode, done.stderr[-2000:]))
    with open(metrics) as f:
        return json.load(f)


def cell(n):
    collisions = len(n["collisions"])
    controller_failures = sum(e["kind"] == "controller_failed" for e in n["events"])
    text = ("%s, %.1f s, SPL %.2f, stalled %.1f s, %d recoveries, %d controller failures, %d cycles blocked by "
            "phantoms (%.1f s), %d into the unseen, %d collisions") % (
        "reached" if n["success"] else "NOT reached", n["time_to_goal_s"], n["spl"], n["stalled_s"], n["recoveries"],
        controller_failures, n["blocked_cycles"], n["blocked_time_s"], n["unseen_cycles"], collisions)
    if not n["success"]:
        text += " (%s)" % n["outcome"]
    return text


def drives(sweep):
    out = []
    for path in sorted(glob.glob(os.path.join(sweep, "*", "metrics.json"))):
        with open(path) as f:
            m = json.load(f)
        if "navigation" in m:
            out.append(m)
    return out


def p95(values):
    v = sorted(values)
    return v[min(len(v) - 1, int(math.ceil(0.95 * len(v))) - 1)] if v else float("nan")


def worlds_table(stvl_dir, ours_dir):
    columns = [drives(stvl_dir), drives(ours_dir)]
    def row(label, f):
        return "| %s | %s | %s |" % (label, f(columns[0]), f(columns[1]))
    n = lambda ms: [m["navigation"] for m in ms]
    reached = lambda ms: [x for x in n(ms) if x["success"]]
    mean = lambda v: sum(v) / len(v) if v else float("nan")
    lines = ["| figure | STVL's behaviour | ours (the fixes) |", "|---|---|---|",
             row("drives", lambda ms: str(len(ms))),
             row("goal reached", lambda ms: "%d of %d" % (len(reached(ms)), len(ms))),
             row("time to goal: mean (p95)", lambda ms: "%.1f s (%.1f s)" % (
                 mean([x["time_to_goal_s"] for x in reached(ms)]), p95([x["time_to_goal_s"] for x in reached(ms)]))),
             row("SPL: mean", lambda ms: "%.3f" % mean([x["spl"] for x in n(ms)])),
             row("recoveries per world: mean (worlds with any)", lambda ms: "%.2f (%d)" % (
                 mean([x["recoveries"] for x in n(ms)]), sum(1 for x in n(ms) if x["recoveries"]))),
             row("collisions per world: mean (worlds with any)", lambda ms: "%.2f (%d)" % (
                 mean([len(x["collisions"]) for x in n(ms)]), sum(1 for x in n(ms) if x["collisions"]))),
             row("time stalled per world: mean", lambda ms: "%.1f s" % mean([x["stalled_s"] for x in n(ms)])),
             row("blocked by phantoms: mean s per world (worlds with any)", lambda ms: "%.2f s (%d)" % (
                 mean([x["blocked_time_s"] for x in n(ms)]), sum(1 for x in n(ms) if x["blocked_time_s"] > 0))),
             row("planning cycles into the unseen: mean per world (worlds with any)", lambda ms: "%.2f (%d)" % (
                 mean([x["unseen_cycles"] for x in n(ms)]), sum(1 for x in n(ms) if x["unseen_cycles"]))),
             row("final phantom obstacles: mean", lambda ms: "%.2f" % mean(
                 [m["evaluation"]["final"]["phantom_obstacles"] for m in ms]))]
    failed = [(m["scenario"], m["navigation"]["outcome"]) for m in columns[0] + columns[1]
              if not m["navigation"]["success"]]
    return "\n".join(lines), failed


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--bench")
    ap.add_argument("--out")
    ap.add_argument("--only", action="append")
    ap.add_argument("--worlds", nargs=2, metavar=("STVL_SWEEP", "OURS_SWEEP"))
    a = ap.parse_args()
    if a.worlds:
        table, failed = worlds_table(*a.worlds)
        print(table)
        for scenario, outcome in failed:
            print("not reached: %s: %s" % (scenario, outcome))
        return
    if not a.bench or not a.out:
        ap.error("--bench and --out (or --worlds)")
    rows = []
    for name, (scenario, common, stvl, ours, what) in TWINS.items():
        if a.only and name not in a.only:
            continue
        s = run(a.bench, a.out, name, "stvl", common + stvl)["navigation"]
        o = run(a.bench, a.out, name, "ours", common + ours)["navigation"]
        rows.append("| %s (`%s`) | %s | %s |" % (what, scenario, cell(s), cell(o)))
    print("| failure mode (scenario) | STVL's behaviour | the fix |")
    print("|---|---|---|")
    print("\n".join(rows))


if __name__ == "__main__":
    main()
