#!/usr/bin/python3
"""Bounds on the voxel count `stvl-bench replay --filter none` must give for a static camera's recording,
computed here independently of the bench (Debian's python3-rosbag for bags, zlib for PNGs).

  expected_replay_voxels.py --bag BAG TOPIC UNIT_M --pose x,y,z      (level camera_link at x,y,z, axes of the world)
  expected_replay_voxels.py --png DIR --scale M                      (DIR/depth/*.png, DIR/calib/*.yaml local_transform)
      then: --voxel M --range M --band MIN_M MAX_M --fx FX --fy FY --cx CX --cy CY (bags)

Each frame's points within `range` of the optical centre and with world z in the band mark their voxels (STVL's
marking with no decimation). The map after the last frame holds at least the last frame's voxels and at most the
union of every frame's (clearing can only remove older ones). Prints "LOWER UPPER".
"""
import argparse
import math
import os
import re
import struct
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'support'))
from png16 import read_png16  # noqa: E402


def voxels(rows, unit, fx, fy, cx, cy, T, a):
    R, t = T
    out = set()
    for v, row in enumerate(rows):
        for u, d in enumerate(row):
            if d == 0:
                continue
            z = d * unit
            p = ((u - cx) / fx * z, (v - cy) / fy * z, z)
            w = [sum(R[i][j] * p[j] for j in range(3)) + t[i] for i in range(3)]
            if (w[0] - t[0]) ** 2 + (w[1] - t[1]) ** 2 + (w[2] - t[2]) ** 2 > a.range ** 2:
                continue
            if not a.band[0] <= w[2] <= a.band[1]:
                continue
            out.add(tuple(math.floor(c / a.voxel) for c in w))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('--bag', nargs=3)
    ap.add_argument('--pose')
    ap.add_argument('--png')
    ap.add_argument('--scale', type=float, default=0.001)
    ap.add_argument('--voxel', type=float, required=True)
    ap.add_argument('--range', type=float, required=True)
    ap.add_argument('--band', type=float, nargs=2, required=True)
    for k in ('fx', 'fy', 'cx', 'cy'):
        ap.add_argument('--' + k, type=float)
    a = ap.parse_args()
    sets = []
    if a.bag:
        import rosbag
        x, y, z = (float(s) for s in a.pose.split(','))
        # optical (z forward, x right, y down) -> level camera_link (x forward, y left, z up) at (x, y, z)
        T = (((0, 0, 1), (-1, 0, 0), (0, -1, 0)), (x, y, z))
        with rosbag.Bag(a.bag[0]) as bag:
            for _, msg, _ in bag.read_messages(topics=[a.bag[1]]):
                rows = [struct.unpack('<%dH' % msg.width, bytes(msg.data[v * msg.step:v * msg.step + 2 * msg.width]))
                        for v in range(msg.height)]
                sets.append(voxels(rows, float(a.bag[2]), a.fx, a.fy, a.cx, a.cy, T, a))
    else:
        names = sorted((n for n in os.listdir(os.path.join(a.png, 'depth')) if n.endswith('.png')),
                       key=lambda n: int(re.sub(r'\D', '', n) or 0))
        for n in names:
            text = open(os.path.join(a.png, 'calib', n[:-4] + '.yaml')).read()
            numbers = lambda key: [float(s) for s in re.search(key + r':.*?data:\s*\[([^\]]*)\]', text, re.S).group(1).split(',')]
            K, L = numbers('camera_matrix'), numbers('local_transform')
            T = ((L[0:3], L[4:7], L[8:11]), (L[3], L[7], L[11]))
            width, height, values = read_png16(os.path.join(a.png, 'depth', n))
            rows = [values[v * width:(v + 1) * width] for v in range(height)]
            sets.append(voxels(rows, a.scale, K[0], K[4], K[2], K[5], T, a))
    union = set().union(*sets)
    print(len(sets[-1]), len(union))


if __name__ == '__main__':
    sys.exit(main())
