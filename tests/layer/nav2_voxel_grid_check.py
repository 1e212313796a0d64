#!/usr/bin/python3
"""An independent model of nav2's 3D line walk (nav2_voxel_grid raytraceLine / bresenham3D, navigation2 main
a3a97043), written from its description in voxel (x, y, z) coordinates rather than nav2's column index and bit
mask, and compared with layer/nav2_voxel_grid.hpp's walk.

    nav2_voxel_grid_check.py                      prints the voxels of a few lines
    nav2_voxel_grid_check.py --compare WALKER     runs WALKER (tests/layer/nav2_voxel_grid_walk) on random lines
                                                  (--lines N, --seed S) and exits 1 on the first difference

The walk, as nav2 describes it: endpoints are real cell coordinates; a line whose endpoint has a coordinate at or
past the grid's size is refused (here also one at or below -1, where nav2 would index outside its array). With
length L = |p1 - p0|: nothing when int(L) < min_length; otherwise the start moves min_length along the line. Each
axis has d = int(end) - int(start) cells to cross; the dominant axis is x if |dx| >= max(|dy|, |dz|), else y if
|dy| >= |dz|, else z. The walk takes min(int(min(1, max_length / L) * |d_dom|), |d_dom|) steps: at each it visits
the current voxel, moves one cell on the dominant axis, and for each other axis adds |d| to an error that started
at |d_dom| // 2; when the error reaches |d_dom| it moves one cell on that axis and loses |d_dom|. Then it visits
the voxel it ended on.
"""
import argparse
import math
import random
import subprocess
import sys

NO_MAX = 2**32 - 1  # nav2's UINT_MAX default


def inside(p, size):
    return all(c > -1.0 and c < s for c, s in zip(p, size))


def walk(p0, p1, size, max_length=NO_MAX, min_length=0):
    """The voxels visited, in order, or None when an endpoint is outside the grid."""
    if not inside(p0, size) or not inside(p1, size):
        return None
    length = math.sqrt((p0[0] - p1[0]) ** 2 + (p0[1] - p1[1]) ** 2 + (p0[2] - p1[2]) ** 2)
    if int(length) < min_length:
        return []
    scale, start = 1.0, list(p0)
    if length > 0.0:
        scale = min(1.0, max_length / length)
        start = [p0[a] + (p1[a] - p0[a]) / length * min_length for a in range(3)]
    if not inside(start, size):
        return None
    d = [int(p1[a]) - int(start[a]) for a in range(3)]
    n = [abs(v) for v in d]
    dom = 0 if n[0] >= max(n[1], n[2]) else (1 if n[1] >= n[2] else 2)
    voxel = [int(c) for c in start]
    error = [n[dom] // 2] * 3
    visited = []
    for _ in range(min(int(scale * n[dom]), n[dom])):
        visited.append(tuple(voxel))
        voxel[dom] += 1 if d[dom] > 0 else -1
        for a in range(3):
            if a == dom:
                continue
            error[a] += n[a]
            if error[a] >= n[dom]:
                voxel[a] += 1 if d[a] > 0 else -1
                error[a] -= n[dom]
    visited.append(tuple(voxel))
    return visited


def fmt(visited):
    return "outside" if visited is None else " ".join("%d,%d,%d" % v for v in visited)


def random_lines(count, seed):
    rng = random.Random(seed)
    lines = []
    for i in range(count):
        size = (rng.randint(1, 40), rng.randint(1, 40), rng.randint(1, 16))
        # Mostly inside, a few just outside (at the size, or below -1) to exercise the refusal.
        def coord(s):
            r = rng.random()
            if r < 0.03:
                return float(s)
            if r < 0.05:
                return -1.0 - rng.random()
            if r < 0.10:
                return float(rng.randint(0, s - 1))  # on a cell boundary
            return rng.uniform(-0.99, s - 1e-9)
        p0 = tuple(coord(s) for s in size)
        p1 = tuple(coord(s) for s in size)
        max_length = NO_MAX if i % 3 == 0 else rng.randint(0, 50)
        min_length = 0 if i % 4 == 0 else rng.randint(0, 20)
        lines.append((size, p0, p1, max_length, min_length))
    return lines


def compare(walker, count, seed):
    lines = random_lines(count, seed)
    # repr() gives the shortest text that reads back to the same double, so both sides walk the same line.
    text = "".join("%d %d %d %s %s %s %s %s %s %d %d\n" % (*size, *map(repr, p0), *map(repr, p1), mx, mn)
                   for size, p0, p1, mx, mn in lines)
    out = subprocess.run([walker], input=text, capture_output=True, text=True, check=True).stdout.splitlines()
    if len(out) != len(lines):
        print("nav2_voxel_grid_check: %d lines sent, %d answers" % (len(lines), len(out)))
        return 1
    refused = 0
    for (size, p0, p1, mx, mn), got in zip(lines, out):
        want = fmt(walk(p0, p1, size, mx, mn))
        refused += want == "outside"
        if got.strip() != want:
            print("nav2_voxel_grid_check: size %s, %r -> %r, max %d, min %d\n  C++:    %s\n  Python: %s"
                  % (size, p0, p1, mx, mn, got, want))
            return 1
    print("nav2_voxel_grid_check: %d lines agree (%d refused as outside the grid)" % (len(lines), refused))
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--compare", metavar="WALKER")
    parser.add_argument("--lines", type=int, default=200)
    parser.add_argument("--seed", type=int, default=20240611)
    args = parser.parse_args()
    if args.compare:
        return compare(args.compare, args.lines, args.seed)
    size = (10, 10, 16)
    for p0, p1, mx, mn in [((0, 0, 0), (5, 2, 1), NO_MAX, 0), ((0, 0, 0), (5, 2, 1), 3, 0),
                           ((0, 0, 0), (1, 2, 5), NO_MAX, 0), ((0.5, 0.5, 0.5), (9.5, 0.5, 0.5), 5, 3),
                           ((1, 1, 1), (10, 1, 1), NO_MAX, 0)]:
        print("%s -> %s max %d min %d: %s" % (p0, p1, mx, mn, fmt(walk(p0, p1, size, mx, mn))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
