#!/usr/bin/python3
"""Compares the first depth images of a bag with 16-bit PNGs (depth_00000.png, ...) written by `stvl-bench render`.

Usage: compare_bag_depth.py BAG RENDER_DIR. Exit 0 when every PNG equals the bag's image of the same index.
PNGs are decoded by tests/support/png16.py (16-bit greyscale, non-interlaced, as stvl-bench writes them).
"""
import glob
import os
import struct
import sys

import rosbag

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "support"))
from png16 import read_png16  # noqa: E402


def main():
    bag_path, render_dir = sys.argv[1], sys.argv[2]
    pngs = sorted(p for p in glob.glob(os.path.join(render_dir, "depth_*.png")) if not p.endswith("_color.png"))
    images = []
    with rosbag.Bag(bag_path) as bag:
        for _, msg, _ in bag.read_messages(topics=["/camera/depth/image_rect_raw"]):
            images.append(struct.unpack("<%dH" % (msg.width * msg.height), msg.data) if not msg.is_bigendian else None)
            if len(images) == len(pngs):
                break
    if not pngs or len(images) < len(pngs):
        print("FAIL: %d PNGs, %d bag images" % (len(pngs), len(images)))
        return 1
    for path, image in zip(pngs, images):
        _, _, png = read_png16(path)
        diff = sum(1 for a, b in zip(png, image) if a != b)
        if diff:
            print("FAIL: %s differs from the bag's image in %d pixels" % (os.path.basename(path), diff))
            return 1
    print("bag depth images equal %d rendered frames" % len(pngs))
    return 0


if __name__ == "__main__":
    sys.exit(main())
