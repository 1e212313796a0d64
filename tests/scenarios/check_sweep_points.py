"""A sweep folder's points after `stvl-bench sweep --collect`: every point passed, ran with its own voxel size and
seed, and ran 0.4 s. Usage: /usr/bin/python3 check_sweep_points.py DIR COUNT (check_sweep_engines.sh, _slurm.sh)."""
import csv
import json
import os
import sys

folder, count = sys.argv[1], int(sys.argv[2])
rows = list(csv.DictReader(open(os.path.join(folder, "sweep.csv"))))
assert len(rows) == count, f"{len(rows)} rows, expected {count}"
for r in rows:
    m = json.load(open(os.path.join(folder, r["point"], "metrics.json")))
    assert r["state"] == "passed", r
    assert abs(m["voxel_size_m"] - float(r["voxel-size"])) < 1e-12, (m["voxel_size_m"], r)
    assert str(m["seed"]) == r["seed"], (m["seed"], r)
    assert m["sim_time_s"] <= 0.4 + 1e-9 and m["frames"] >= 6, m["frames"]
print(f"{folder}: {count} points passed with their own voxel size and seed")
