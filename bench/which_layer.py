#!/usr/bin/python3
"""Which 3D layer for my robot: STVL, nav2's VoxelLayer and nav2's ObstacleLayer on the same drives.

Runs `stvl-bench sweep` once per layer configuration over the shipped scenarios (every scenarios/*.yaml) and, with
--worlds N, over N generated offices (`--worlds generate:1..N`), then reads every point's metrics.json and writes one
markdown table per world set: for each layer the mean over the drives of the 3D precision and recall (voxel layers
only), the costmap precision and recall, the phantoms (final and the worst snapshot), the lethal cells in free space
along the path, the clearing of moved bodies (stale voxels never cleared, the slowest clearing) and of hidden ones
(true voxels cleared unseen), the lethal cells on the robot, and the drives whose checks all passed; each figure's worst drive is named. (The layers' CPU cost is
the layer benchmark's, `stvl-bench-bench layers`: timings of parallel sweeps share the cores.)

The layers as their documentation configures them for a D435 on a ground robot:
  stvl           the scenario's own STVL settings (STVL's README example: 0.05 m voxels, 15 s linear decay, frustum
                 clearing), with the bench's fixes where a scenario turns them on (ray-cast clearing, clearing along
                 pixels without a return, the footprint voxel clearing, the flying-pixel filter);
  stvl_plain     the same without the map's fixes (frustum clearing, no clearing on no return, no footprint voxel
                 clearing): STVL's own behaviour but for the per-camera edge filter of flying_pixels.yaml;
  nav2_voxel     nav2_bringup's local costmap voxel_layer (jazzy nav2_params.yaml: z_resolution 0.05, z_voxels 16 from
                 origin_z 0, so it marks up to 0.8 m; max_obstacle_height 2.0, mark_threshold 0; the source's
                 obstacle_max_range 2.5, raytrace_max_range 3.0);
  nav2_voxel_2m  the same with z_resolution 0.125 (16 levels up to 2.0 m: the band the scenarios mark);
  nav2_obstacle  nav2's ObstacleLayer with nav2's defaults (max_obstacle_height 2.0, ranges 2.5 / 3.0, the marking
                 rule of nav2 today, #5697 + #6092).
Each nav2 layer runs in a rolling window holding its reach (2 * 3.0 + 1 = 7 m at map.voxel_size 0.05) and, like STVL
here, updates once per camera instant (nav2's update_frequency 0).

Usage: bench/which_layer.py --bin build/bin/stvl-bench --out out/which_layer [--worlds 100] [--jobs 2]
       [--layers stvl,nav2_voxel,...] [--table-only] [--rerun shipped,generated]
Exit 0 when every point ran (whatever its checks said), 1 when a point did not run, 2 on bad usage.
"""
import argparse
import glob
import json
import math
import os
import subprocess
import sys

LAYERS = {
    "stvl": [],
    "stvl_plain": ["map.clearing_mode=frustum", "map.observation.clear_on_no_return=false",
                   "map.clear_footprint_voxels_below=0"],
    "nav2_voxel": ["map.layer_type=nav2_voxel", "map.nav2_layer.z_resolution=0.05", "map.nav2_layer.z_voxels=16"],
    "nav2_voxel_2m": ["map.layer_type=nav2_voxel", "map.nav2_layer.z_resolution=0.125",
                      "map.nav2_layer.z_voxels=16"],
    "nav2_obstacle": ["map.layer_type=nav2_obstacle"],
}


def sweep(binary, out, layer, worlds, jobs):
    """One sweep of one layer over the worlds (a generate:1..N spec or a comma-separated list of scenario files)."""
    command = [binary, "sweep", "--worlds", worlds, "--jobs", str(jobs), "--out", out]
    for setting in LAYERS[layer]:
        command += ["--set", setting]
    print("which_layer:", " ".join(command), flush=True)
    return subprocess.run(command, stdout=subprocess.DEVNULL, check=False).returncode


def figures(metrics):
    """The figures of one drive's metrics.json (None where the layer cannot have one)."""
    e = metrics["evaluation"]
    mean, final = e["mean"], e["final"]
    voxels = e.get("voxels_3d", True)
    return {
        "precision": mean["precision"] if voxels else None,
        "recall": mean["recall"] if voxels else None,
        "costmap_precision": mean["costmap_precision"],
        "costmap_recall": mean["costmap_recall"],
        "final_phantoms": final["phantom_obstacles"],
        "worst_phantoms": mean["max_phantom_obstacles"],
        "path_free_lethal": mean["max_path_free_lethal"],
        # moved bodies' stale voxels the camera saw through: never cleared, the slowest cleared, true voxels cleared
        # while hidden (voxel layers only); lethal cells on the robot at worst
        "not_cleared": e["clearing"]["not_cleared"] if voxels else None,
        "clearing_latency": e["clearing"]["max_latency_s"] if voxels else None,
        "hidden_false_clears": e["failure_modes"]["occlusion"]["hidden_false_clears"] if voxels else None,
        "self_lethal": e["failure_modes"]["self_marking"]["max_self_lethal_cells"],
        "passed": 1.0 if metrics["passed"] else 0.0,
    }


# (key, column title, format, whether a higher value is better)
COLUMNS = [
    ("precision", "3D P", "{:.3f}", True), ("recall", "3D R", "{:.3f}", True),
    ("costmap_precision", "costmap P", "{:.3f}", True), ("costmap_recall", "costmap R", "{:.3f}", True),
    ("final_phantoms", "final phantoms", "{:.2f}", False), ("worst_phantoms", "worst phantoms", "{:.2f}", False),
    ("path_free_lethal", "path cells", "{:.1f}", False), ("not_cleared", "never cleared", "{:.0f}", False),
    ("clearing_latency", "clearing latency s", "{:.2f}", False), ("hidden_false_clears", "hidden clears", "{:.0f}", False),
    ("self_lethal", "self cells", "{:.1f}", False), ("passed", "all checks pass", "{:.0%}", True),
]


def table(rows_by_layer, title):
    """Markdown: one row per layer, each figure's mean over the drives and its worst drive."""
    lines = ["**" + title + "**", "",
             "| layer | drives | " + " | ".join(c[1] for c in COLUMNS) + " |",
             "|---|---|" + "---|" * len(COLUMNS)]
    for layer, rows in rows_by_layer.items():
        cells = []
        for key, _, fmt, higher in COLUMNS:
            values = [(r[key], name) for name, r in rows if r[key] is not None]
            if not values:
                cells.append("n/a")
                continue
            mean = sum(v for v, _ in values) / len(values)
            worst = min(values) if higher else max(values)
            cell = fmt.format(mean)
            if key != "passed" and len(values) > 1:
                cell += " (" + fmt.format(worst[0]) + " " + worst[1] + ")"
            cells.append(cell)
        lines.append("| " + layer + " | " + str(len(rows)) + " | " + " | ".join(cells) + " |")
    return "\n".join(lines) + "\n"


def collect(out):
    """(point name, figures) of every point of a sweep folder, in point order."""
    rows = []
    for path in sorted(glob.glob(os.path.join(out, "*", "metrics.json"))):
        point = os.path.basename(os.path.dirname(path))
        if point == "worlds":
            continue
        with open(path, encoding="utf-8") as f:
            metrics = json.load(f)
        rows.append((metrics.get("scenario", point), figures(metrics)))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--bin", required=True)
    parser.add_argument("--out", required=True)
    parser.add_argument("--worlds", type=int, default=0, help="generated offices (0: shipped scenarios only)")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--layers", default=",".join(LAYERS))
    parser.add_argument("--scenarios", default="scenarios", help="the folder of the shipped scenarios")
    parser.add_argument("--table-only", action="store_true", help="only read the sweeps already in --out")
    parser.add_argument("--rerun", default="shipped,generated",
                        help="which world sets to run (the others are only read from --out)")
    args = parser.parse_args()
    layers = args.layers.split(",")
    if any(layer not in LAYERS for layer in layers):
        print("which_layer: --layers: expected some of " + ", ".join(LAYERS), file=sys.stderr)
        return 2
    # A scenario that takes its layer from a ROS parameter file (ros_params) runs with that file's layer only.
    shipped = [p for p in sorted(glob.glob(os.path.join(args.scenarios, "*.yaml")))
               if "ros_params:" not in open(p, encoding="utf-8").read()]
    sets = [("shipped", ",".join(shipped))]
    if args.worlds > 0:
        sets.append(("generated", "generate:1..%d" % args.worlds))
    failed = 0
    report = []
    for set_name, worlds in sets:
        rows = {}
        for layer in layers:
            out = os.path.join(args.out, set_name, layer)
            if not args.table_only and set_name in args.rerun.split(","):
                sweep(args.bin, out, layer, worlds, args.jobs)
            rows[layer] = collect(out)
            expected = len(worlds.split(",")) if set_name == "shipped" else args.worlds
            failed += expected - len(rows[layer])
        title = ("Shipped scenarios" if set_name == "shipped" else "%d generated offices" % args.worlds)
        report.append(table(rows, title + ": mean over the drives (worst drive in brackets)"))
    text = "\n".join(report)
    with open(os.path.join(args.out, "which_layer.md"), "w", encoding="utf-8") as f:
        f.write(text)
    print(text)
    if failed:
        print("which_layer: %d points did not run" % failed, file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
