#!/usr/bin/env python3
"""Compares the voxel sets of two maps written by stvl-bench (map.ply: binary little-endian, float x y z of each
voxel centre, then its double time).

  compare_ply_voxels.py A.ply B.ply VOXEL_SIZE_M MIN_AGREEMENT

Agreement = |A and B| / |A or B| over voxel keys (centre / voxel size, rounded). Prints the counts and exits 1
when the agreement is below MIN_AGREEMENT, 2 on unreadable input.
"""
import struct
import sys


def voxels(path, size):
    with open(path, "rb") as f:
        data = f.read()
    end = data.find(b"end_header\n")
    if end < 0:
        sys.exit(f"{path}: not a PLY file")
    header = data[:end].decode("ascii").splitlines()
    count = next(int(line.split()[2]) for line in header if line.startswith("element vertex"))
    body = data[end + len(b"end_header\n"):]
    record = struct.Struct("<fffd")
    if len(body) != count * record.size:
        sys.exit(f"{path}: {len(body)} bytes of vertices, expected {count * record.size}")
    keys = set()
    for x, y, z, _ in record.iter_unpack(body):
        keys.add((round(x / size - 0.5), round(y / size - 0.5), round(z / size - 0.5)))
    return keys


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__)
    size, minimum = float(sys.argv[3]), float(sys.argv[4])
    try:
        a, b = voxels(sys.argv[1], size), voxels(sys.argv[2], size)
    except OSError as e:
        print(e, file=sys.stderr)
        return 2
    union = a | b
    agreement = len(a & b) / len(union) if union else 1.0
    print(f"A {len(a)} voxels, B {len(b)}, both {len(a & b)}, only A {len(a - b)}, only B {len(b - a)}: "
          f"agreement {agreement:.5f} (required {minimum})")
    return 0 if agreement >= minimum and union else 1


if __name__ == "__main__":
    sys.exit(main())
