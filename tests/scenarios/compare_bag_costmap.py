#!/usr/bin/python3
"""The last /stvl/costmap in a run's bag equals the run's costmap.pgm + costmap.yaml (same cells, size, origin).

  compare_bag_costmap.py RUN.bag RUN_DIR

Exits 1 naming the first difference. Run with /usr/bin/python3 (Debian's rosbag)."""
import sys

import rosbag


def read_pgm(path):
    with open(path, "rb") as f:
        data = f.read()
    parts = data.split(b"\n", 3)
    if parts[0] != b"P5":
        sys.exit("FAIL: %s is not a binary PGM" % path)
    width, height = (int(v) for v in parts[1].split())
    return width, height, parts[3]


def read_origin(path):
    for line in open(path):
        if line.startswith("origin:"):
            return [float(v) for v in line.split("[")[1].split("]")[0].split(",")[:2]]
        if line.startswith("resolution:"):
            pass
    sys.exit("FAIL: no origin in %s" % path)


def main():
    bag_path, run_dir = sys.argv[1], sys.argv[2]
    last = None
    with rosbag.Bag(bag_path) as bag:
        for _, msg, _ in bag.read_messages(topics=["/stvl/costmap"]):
            last = msg
    if last is None:
        sys.exit("FAIL: no /stvl/costmap in %s" % bag_path)
    width, height, pixels = read_pgm(run_dir + "/costmap.pgm")
    if (last.info.width, last.info.height) != (width, height):
        sys.exit("FAIL: bag costmap %dx%d, costmap.pgm %dx%d" % (last.info.width, last.info.height, width, height))
    origin = read_origin(run_dir + "/costmap.yaml")
    if abs(last.info.origin.position.x - origin[0]) > 1e-9 or abs(last.info.origin.position.y - origin[1]) > 1e-9:
        sys.exit("FAIL: bag origin (%r, %r), costmap.yaml %r" % (last.info.origin.position.x, last.info.origin.position.y, origin))
    pgm_value = {100: 0, 0: 254, -1: 205}
    lethal = 0
    for iy in range(height):
        row = height - 1 - iy  # the PGM's top row is the highest y
        for ix in range(width):
            occupancy = last.data[iy * width + ix]
            expected = pgm_value.get(occupancy)
            if expected is None or pixels[row * width + ix] != expected:
                sys.exit("FAIL: cell (%d, %d): bag %d, costmap.pgm %d" % (ix, iy, occupancy, pixels[row * width + ix]))
            lethal += occupancy == 100
    if lethal == 0:
        sys.exit("FAIL: the final costmap has no lethal cell (nothing compared)")
    print("bag costmap == costmap.pgm: %dx%d cells, %d lethal" % (width, height, lethal))


if __name__ == "__main__":
    main()
